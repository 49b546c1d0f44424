"""robomimic / RoboCasa demonstration files (HDF5), read with h5py.

Layout::

    data                      attrs: env_args (JSON: env_name, env_kwargs...),
                              problem_info (LIBERO JSON, has "language_instruction")
    data/demo_0               attrs: num_samples, ep_meta (RoboCasa JSON, has "lang")
    data/demo_0/obs/agentview_image        (T, H, W, 3) uint8, one per camera
    data/demo_0/obs/robot0_eef_pos ...     low-dimensional observations
    data/demo_0/states, actions

Files from robomimic's "low_dim" release hold only simulator states; they must be
re-rendered (`rover generate --source-hdf5`) before a VLM can look at them.
"""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import numpy as np

from rover.episode import Episode
from rover.errors import InputError
from rover.io.plain import sample_positions
from rover.io.source import SourceReader

IMAGE_SUFFIX = "_image"
_DEMO = re.compile(r"^demo_(\d+)$")


def _h5py():
    try:
        import h5py
    except ModuleNotFoundError as exc:  # pragma: no cover - h5py is a core dependency
        raise InputError("reading HDF5 demonstrations needs h5py: pip install h5py") from exc
    return h5py


class HDF5Source(SourceReader):
    """Demos of a robomimic/RoboCasa file; `view`/`?camera=agentview` picks the camera."""

    kind = "hdf5"
    extra_keys = frozenset({"flip"})

    def __init__(self, path: Path, **kwargs: Any) -> None:
        super().__init__(path, **kwargs)
        self.flip = self.options.get("flip", "0").lower() in ("1", "true", "yes")
        h5py = _h5py()
        try:
            with h5py.File(self.path, "r") as f:
                if "data" not in f or not isinstance(f["data"], h5py.Group):
                    raise InputError(f"{self.path}: no 'data' group (not a robomimic file)")
                demos = [k for k in f["data"] if _DEMO.match(k)]
                self._demos = sorted(demos, key=lambda k: int(_DEMO.match(k)[1]))
                self._env = _json_attr(f["data"].attrs.get("env_args"))
                self._problem = _json_attr(f["data"].attrs.get("problem_info"))
        except OSError as exc:
            raise InputError(f"{self.path}: unreadable HDF5 file ({_one_line(exc)})") from exc
        if not self._demos:
            raise InputError(f"{self.path}: 'data' holds no demo_N groups")

    def _episode_ids(self) -> list[str]:
        return list(self._demos)

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        if episode_id not in self._demos:
            raise InputError(f"{self.path}: no demo {episode_id!r}")
        h5py = _h5py()
        with h5py.File(self.path, "r") as f:
            demo = f["data"][episode_id]
            obs = demo.get("obs")
            cams = sorted(k for k in (obs or {}) if k.endswith(IMAGE_SUFFIX))
            if not cams:
                raise InputError(
                    f"{self.path}: data/{episode_id}/obs has only states, no *{IMAGE_SUFFIX} "
                    f"observations; re-render it with 'rover generate --source-hdf5 {self.path}'"
                )
            camera = self._pick_camera(cams, episode_id)
            dset = obs[camera]
            field = f"data/{episode_id}/obs/{camera}"
            if dset.ndim != 4 or dset.shape[-1] not in (3, 4) or dset.dtype != np.uint8:
                raise InputError(
                    f"{self.path}: {field} must be uint8 (T, H, W, 3), got "
                    f"{dset.dtype} {tuple(dset.shape)}"
                )
            total = int(dset.shape[0])
            positions = sample_positions(total, frames)
            chunk = dset[:] if len(positions) == total else dset[positions]
            pixels = np.ascontiguousarray(chunk[..., :3])
            ep_meta = _json_attr(demo.attrs.get("ep_meta"))
        if self.flip:
            pixels = np.ascontiguousarray(pixels[:, ::-1])
        names = [c.removesuffix(IMAGE_SUFFIX) for c in cams]
        view = camera.removesuffix(IMAGE_SUFFIX)
        return Episode(
            id=episode_id,
            task=self.task if self.task is not None else self._task_text(ep_meta),
            source=f"hdf5:{self.path}",
            fps=self.fps or 20.0,  # robosuite's default control rate
            frame_indices=positions,
            view_names=names,
            default_view=view,
            views={view: pixels},
            extra={
                "total_frames": total,
                "dataset": self.path.stem,
                "env_name": self._env.get("env_name"),
            },
        )

    def _pick_camera(self, cams: list[str], episode_id: str) -> str:
        if self.view is None:
            for pref in ("agentview_image", "robot0_agentview_center_image"):
                if pref in cams:
                    return pref
            return cams[0]
        for c in cams:
            if self.view in (c, c.removesuffix(IMAGE_SUFFIX)):
                return c
        raise InputError(
            f"{self.path}: data/{episode_id}/obs has no camera {self.view!r}; cameras: "
            + ", ".join(c.removesuffix(IMAGE_SUFFIX) for c in cams)
        )

    def _task_text(self, ep_meta: dict[str, Any]) -> str:
        """RoboCasa: the demo's `ep_meta["lang"]`; LIBERO: `problem_info` of the file."""
        for value in (ep_meta.get("lang"), self._problem.get("language_instruction")):
            if isinstance(value, list | tuple):
                value = " ".join(str(v) for v in value if v)
            if value and str(value).strip():
                return str(value).strip()
        return ""

    def task_of(self, episode_id: str) -> str:
        if self.task is not None:
            return self.task
        if episode_id not in self._demos:
            raise InputError(f"{self.path}: no demo {episode_id!r}")
        with _h5py().File(self.path, "r") as f:
            return self._task_text(_json_attr(f["data"][episode_id].attrs.get("ep_meta")))


def _json_attr(value: Any) -> dict[str, Any]:
    if value is None:
        return {}
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    try:
        data = json.loads(value)
    except (TypeError, json.JSONDecodeError):
        return {}
    return data if isinstance(data, dict) else {}


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else exc.__class__.__name__
