"""`rover generate` on an executor whose tasks do not see the dataset directory (Ray).

A task gets what it needs by value (the work item, the config, the task's expert demos as
bytes through the object store), generates the episode with the very function the local
pool runs (`rover.sim.generate.generate_episode`) into a scratch folder on its own node,
and returns the episode's files as bytes. The driver writes them into `DIR/episodes/<id>`
with the same `.part` + rename as `write_episode`, so a killed run leaves only `.part`
folders, which a resume redoes. Same seed, same bytes: nothing here chooses anything.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import tempfile
import uuid
from collections.abc import Callable
from pathlib import Path
from typing import Any

SCRATCH = "rover-exec"


def write_bytes_atomic(path: Path, data: bytes) -> None:
    """Write a file whole (unique temp name + rename): concurrent writers cannot tear it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"{path.name}.{uuid.uuid4().hex[:8]}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def write_folder_atomic(final: Path, files: dict[str, bytes]) -> None:
    """Write a folder of files as `write_episode` does: into `<name>.part`, then rename."""
    tmp = final.with_name(final.name + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    for name, data in files.items():
        if Path(name).name != name:
            raise ValueError(f"episode file name {name!r} is not a plain name")
        (tmp / name).write_bytes(data)
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)


def _quiet() -> None:
    import logging

    logging.getLogger("robosuite").setLevel(logging.ERROR)


# ------------------------------------------------------------------ on a worker
def demo_job(task: str, cfg: Any) -> tuple[str, bytes]:
    """Run the task's scripted expert demos in a scratch folder; return the HDF5 bytes."""
    from rover.sim.generate import make_demos

    _quiet()
    scratch = Path(tempfile.mkdtemp(prefix="rover-demos-"))
    try:
        path = make_demos(task, cfg, scratch)
        return task, path.read_bytes()
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def episode_job(item: Any, cfg: Any, digest: str, demos: bytes) -> tuple[str, dict[str, bytes]]:
    """Generate one episode on this node; return (id, {file name: bytes}).

    The demos land once per node under the system temp folder, named by `digest` (config
    and demo content), so the worker's cached simulator and demos are reused by the next
    episode of the same dataset and never mixed with another's.
    """
    from rover.sim.generate import generate_episode

    _quiet()
    root = Path(tempfile.gettempdir()) / SCRATCH / digest
    demo = root / "demos" / f"{item.task}.hdf5"
    if not demo.exists():
        write_bytes_atomic(demo, demos)
    eid = generate_episode(item, cfg, root)
    folder = root / "episodes" / eid
    try:
        files = {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return eid, files


# ------------------------------------------------------------------ on the driver
def generate_remote(
    executor: Any,
    cfg: Any,
    out: Path,
    todo: list[Any],
    report: Callable[[str, int, int], None],
) -> list[str]:
    """Demos, then every pending episode, on `executor`; the driver writes every file."""
    from rover.sim.generate import make_demos

    demo_dir = out / "demos"
    tasks = sorted({it.task for it in todo})
    have = [t for t in tasks if (demo_dir / f"{t}.hdf5").exists()]
    missing = [t for t in tasks if t not in have]
    if cfg.source_hdf5:  # the user's file is on this machine: copying it is the whole job
        for t in missing:
            make_demos(t, cfg, demo_dir)
        have, missing = tasks, []
    for i, _ in enumerate(have):
        report("demos", i + 1, len(tasks))
    for i, (task, data) in enumerate(
        executor.map_unordered(demo_job, [(t, cfg) for t in missing], num_cpus=1)
    ):
        write_bytes_atomic(demo_dir / f"{task}.hdf5", data)
        report("demos", len(have) + i + 1, len(tasks))
    blobs = {}
    settings = cfg.model_dump_json().encode()
    for t in tasks:
        data = (demo_dir / f"{t}.hdf5").read_bytes()
        digest = hashlib.sha256(settings + b"\0" + data).hexdigest()[:20]
        blobs[t] = (digest, executor.put(data))
    written: list[str] = []
    report("episodes", 0, len(todo))
    jobs = [(it, cfg, *blobs[it.task]) for it in todo]
    for eid, files in executor.map_unordered(episode_job, jobs, num_cpus=1):
        write_folder_atomic(out / "episodes" / eid, files)
        written.append(eid)
        report("episodes", len(written), len(todo))
    return written
