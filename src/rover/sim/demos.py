"""Expert demonstrations in the robomimic HDF5 layout (read and write).

Layout (robomimic / RoboCasa)::

    data.attrs["env_args"]   JSON {"env_name", "type": 1, "env_kwargs": {...}}
    data/demo_N/states       (T, S) flat MuJoCo states, state t before action t
    data/demo_N/actions      (T, A)
    data/demo_N.attrs        num_samples, model_file (MJCF XML), ep_meta (JSON)

We write our scripted experts in this layout, and read any such file a user already has,
so a robomimic or RoboCasa dataset can serve as the source dataset D_src of the
generator (`rover generate --source-hdf5 FILE`): its states are replayed in the
environment its `env_args` names.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from rover.errors import InputError


@dataclass
class DemoRecord:
    """One stored demonstration."""

    name: str  # "demo_0"
    states: np.ndarray
    actions: np.ndarray
    model_file: str | None = None
    ep_meta: dict[str, Any] = field(default_factory=dict)


def write_demos(
    path: Path, env_name: str, env_kwargs: dict[str, Any], demos: list[DemoRecord]
) -> None:
    """Write demonstrations atomically (a `.tmp` file renamed into place)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    with h5py.File(tmp, "w") as f:
        data = f.create_group("data")
        data.attrs["env_args"] = json.dumps(
            {"env_name": env_name, "type": 1, "env_kwargs": env_kwargs}
        )
        total = 0
        for d in demos:
            g = data.create_group(d.name)
            g.create_dataset("states", data=np.asarray(d.states, dtype=np.float64))
            g.create_dataset("actions", data=np.asarray(d.actions, dtype=np.float64))
            g.attrs["num_samples"] = len(d.actions)
            if d.model_file:
                g.attrs["model_file"] = d.model_file
            g.attrs["ep_meta"] = json.dumps(d.ep_meta)
            total += len(d.actions)
        data.attrs["total"] = total
    tmp.replace(path)


def read_env_args(path: Path) -> dict[str, Any]:
    """The `env_args` JSON of a robomimic file: env_name and env_kwargs."""
    with _open(path) as f:
        raw = f["data"].attrs.get("env_args")
        if raw is None:
            raise InputError(f"{path}: no data.attrs['env_args'] (not a robomimic file?)")
        return json.loads(raw)


def read_demos(path: Path, limit: int | None = None) -> list[DemoRecord]:
    """Demonstrations of a robomimic/RoboCasa HDF5 file, in demo-number order."""
    out: list[DemoRecord] = []
    with _open(path) as f:
        names = sorted(f["data"].keys(), key=_demo_number)
        for name in names[:limit]:
            g = f["data"][name]
            if "states" not in g:
                raise InputError(f"{path}: {name} has no 'states' (cannot replay it)")
            model = g.attrs.get("model_file")
            meta = g.attrs.get("ep_meta")
            out.append(
                DemoRecord(
                    name=name,
                    states=np.asarray(g["states"], dtype=np.float64),
                    actions=np.asarray(g["actions"], dtype=np.float64)
                    if "actions" in g
                    else np.zeros((len(g["states"]), 7)),
                    model_file=model if isinstance(model, str) else None,
                    ep_meta=json.loads(meta) if isinstance(meta, str) and meta else {},
                )
            )
    if not out:
        raise InputError(f"{path}: no demonstrations under data/")
    return out


def _open(path: Path) -> h5py.File:
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such file")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"{path}: not a readable HDF5 file ({exc})") from exc
    if "data" not in f:
        f.close()
        raise InputError(f"{path}: no 'data' group (not a robomimic/RoboCasa file)")
    return f


def _demo_number(name: str) -> tuple[int, str]:
    tail = name.rsplit("_", 1)[-1]
    return (int(tail), name) if tail.isdigit() else (1 << 30, name)
