"""`rover generate --executor ray` against `--workers 2` on this machine, and a scaling model.

Usage: python benchmarks/ray_scaling.py [--task Lift] [--per-level 25] [--size 64]
       [--frames 30] [--cpus 2] [--node-cpus 8] [--model-episodes 10000]

Generates the same dataset twice from scratch (a task's every level, ``--per-level`` videos
each: 4 x 25 = 100 for Lift): once with a local pool of ``--cpus`` workers, once on a
fresh local Ray limited to ``--cpus`` CPUs, and checks the two wrote identical episode
files. The target is Ray within 1.3x of the pool. Then it measures what the model needs:
Ray's overhead per task (no-op tasks returning an episode's worth of bytes) and the
driver's time to write one episode's files, and prints the predicted wall time of
``--model-episodes`` episodes on 1-16 nodes of ``--node-cpus`` CPUs. That table is a
model built from this machine's numbers, not a cluster measurement: it assumes episodes
of equal cost, workers as fast as this machine's, and no network limit.
"""

from __future__ import annotations

import argparse
import math
import os
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

from rover.exec.generate_job import write_folder_atomic
from rover.exec.ray_cluster import RayExecutor
from rover.sim.generate import GenerateConfig, generate


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def _timed_generate(cfg: GenerateConfig, out: Path, **kw) -> tuple[float, float]:
    """(total wall, wall of the episode phase) of one generate call."""
    marks: dict[str, float] = {}

    def on_progress(stage: str, done: int, total: int) -> None:
        if stage == "episodes" and done == 0:
            marks["episodes"] = time.perf_counter()

    start = time.perf_counter()
    generate(cfg, out, on_progress=on_progress, **kw)
    end = time.perf_counter()
    return end - start, end - marks.get("episodes", start)


def _files(root: Path) -> dict[str, bytes]:
    eps = root / "episodes"
    return {str(p.relative_to(eps)): p.read_bytes() for p in eps.rglob("*") if p.is_file()}


def _noop(nbytes: int) -> tuple[str, dict[str, bytes]]:
    return "noop", {"episode.json": b"x" * nbytes}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--task", default="Lift")
    ap.add_argument("--per-level", type=int, default=25)
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--cpus", type=int, default=2)
    ap.add_argument("--node-cpus", type=int, default=8)
    ap.add_argument("--model-episodes", type=int, default=10_000)
    args = ap.parse_args()
    os.environ.setdefault("MUJOCO_GL", "egl")
    cfg = GenerateConfig(
        tasks=[args.task],
        per_level=args.per_level,
        frames=args.frames,
        views=["left"],
        size=args.size,
        seed=0,
        demos=1,
    )
    console = Console(width=120)
    console.print(f"load average before: {_load()}")
    with tempfile.TemporaryDirectory(prefix="ray-scaling-") as tmp:
        tmp_path = Path(tmp)
        local_wall, local_eps = _timed_generate(cfg, tmp_path / "local", workers=args.cpus)
        n = len(_files(tmp_path / "local")) // 2  # episode.json + one MP4 each
        t0 = time.perf_counter()
        with RayExecutor(num_cpus=args.cpus) as ex:  # generate's own `with` keeps it open
            ray_start = time.perf_counter() - t0
            ray_wall, ray_eps = _timed_generate(cfg, tmp_path / "ray", executor=ex)
            same = _files(tmp_path / "local") == _files(tmp_path / "ray")
            sizes = [len(b) for b in _files(tmp_path / "ray").values()]
            ep_bytes = int(sum(sizes) / max(n, 1))
            # Ray's own cost per task: no-op tasks that return an episode's worth of bytes
            probes = 200
            p0 = time.perf_counter()
            for _ in ex.map_unordered(_noop, [(ep_bytes,)] * probes, num_cpus=1):
                pass
            probe_wall = time.perf_counter() - p0
        # the driver writes every episode itself: its time per episode bounds the scaling
        folders = sorted((tmp_path / "ray" / "episodes").iterdir())
        w0 = time.perf_counter()
        for d in folders:
            files = {p.name: p.read_bytes() for p in d.iterdir()}
            write_folder_atomic(tmp_path / "rewrite" / d.name, files)
        write_s = (time.perf_counter() - w0) / max(len(folders), 1)
    console.print(f"load average after: {_load()}")

    table = Table(title=f"{n} episodes of {args.task} ({args.size} px, {args.frames} frames)")
    for col in ("executor", "start s", "demos+episodes s", "episodes s", "episodes/min", "x pool"):
        table.add_column(col, justify="right")
    table.add_row(
        f"--workers {args.cpus}", "-", f"{local_wall:.1f}", f"{local_eps:.1f}",
        f"{60 * n / local_wall:.1f}", "1.00",
    )  # fmt: skip
    table.add_row(
        f"--executor ray ({args.cpus} CPUs)", f"{ray_start:.1f}", f"{ray_wall:.1f}",
        f"{ray_eps:.1f}", f"{60 * n / ray_wall:.1f}",
        f"{ray_wall / local_wall:.2f} ({(ray_start + ray_wall) / local_wall:.2f} with start)",
    )  # fmt: skip
    console.print(table)
    console.print(
        f"identical episode files: {'yes' if same else 'NO'}; target: ray within 1.3x of the "
        f"pool (demos+episodes): {'met' if ray_wall <= 1.3 * local_wall else 'NOT met'}"
    )

    t_ep = local_eps * args.cpus / max(n, 1)  # one episode on one core
    o_task = max(0.0, ray_eps * args.cpus / max(n, 1) - t_ep)  # Ray's extra per episode task
    o_probe = probe_wall * args.cpus / probes  # a no-op task's round trip on a worker slot
    driver = probe_wall / probes + write_s  # the driver's serial share per episode
    demos_s = ray_wall - ray_eps
    console.print(
        f"measured: episode {t_ep:.2f} s on one core; Ray overhead per episode task "
        f"{o_task * 1000:.0f} ms (no-op probe: {o_probe * 1000:.1f} ms per task slot); "
        f"driver per episode {driver * 1000:.1f} ms (collect {probe_wall / probes * 1000:.1f} "
        f"+ write {write_s * 1000:.1f}); {ep_bytes / 1024:.0f} KiB per episode; "
        f"Ray start {ray_start:.1f} s; demos {demos_s:.1f} s"
    )
    model = Table(
        title=f"MODEL (not measured): {args.model_episodes:,} episodes, "
        f"{args.node_cpus} CPUs per node"
    )
    for col in ("nodes", "CPUs", "predicted wall", "episodes/min", "bound by"):
        model.add_column(col, justify="right")
    e = args.model_episodes
    for nodes in (1, 2, 4, 8, 16):
        cpus = nodes * args.node_cpus
        compute = math.ceil(e / cpus) * (t_ep + max(o_task, o_probe))
        collect = e * driver
        wall = ray_start + demos_s + max(compute, collect)
        model.add_row(
            str(nodes),
            str(cpus),
            f"{wall / 60:.1f} min",
            f"{60 * e / wall:.0f}",
            "compute" if compute >= collect else "driver",
        )
    console.print(model)
    console.print(
        "model: wall = Ray start + demos + max(ceil(E / CPUs) x (episode + Ray overhead), "
        "E x driver time per episode); equal episodes, no network limit"
    )


if __name__ == "__main__":
    main()
