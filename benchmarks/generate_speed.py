"""Generator speed vs. its physics-only and render-only ceilings, measured in one run.

Usage: python benchmarks/generate_speed.py [--tasks Lift,PickPlaceCan] [--episodes 4]
       [--frames 30] [--views left,wrist] [--size 128]
       python benchmarks/generate_speed.py --full [--tasks all] [--per-level 3] [--workers 2]
       [--views left,wrist] [--size 256]
       python benchmarks/generate_speed.py --full --preset paper [--views left,wrist] [--keep DIR]

``--full`` times one whole `rover generate` run (every level, ``--per-level`` videos each,
``--workers`` processes, expert demos included), prints the load average before and after
(the machine may be shared: compare runs made under similar load), and lists how many
tries each level needed to meet its milestone (read from the written ``dataset.json``).
``--preset paper`` makes it the paper preset's run (`rover generate --preset paper
--available-only`: the kitchen tasks that exist, Table 5's videos per level, 30/60 frames),
whose target is 30 minutes on 2 cores with 2 workers, 256 px, two views.

Per task, after a warm-up episode (the first episode per process pays for building the
env, the renderer and numba/EGL start-up): the full pipeline (perturb + value + facts +
render + MP4 write) in one process, the physics ceiling (control steps per second with
no rendering) and the render ceiling (frames per second rendering saved states). CPU
seconds include every thread of the process (llvmpipe renders with several).
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from rover.sim.generate import GenerateConfig, _task_state, generate_episode, make_demos, work_items
from rover.sim.tasks import get_task


def _timed(fn) -> tuple[float, float]:
    w, c = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - w, time.process_time() - c


def _load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def full_run(args: argparse.Namespace) -> None:
    """Time one whole generation run and report the tries each level took."""
    from rover.sim.generate import generate
    from rover.sim.tasks import task_names

    counts: dict[str, list[int]] = {}
    if args.preset:  # the paper's shape: its tasks that exist, Table 5's videos per level
        from rover.sim.kitchen.presets import paper_plan

        tasks, counts, note = paper_plan(task_names("all"), available_only=True)
        Console(width=150).print(note)
    else:
        tasks = task_names() if args.tasks == "all" else args.tasks.split(",")
    cfg = GenerateConfig(
        tasks=tasks,
        per_level=args.per_level,
        views=args.views.split(","),
        size=args.size if args.size else 256,
        seed=args.seed,
        level_counts=counts,
    )
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.keep) if args.keep else Path(tmp) / "ds"
        before = _load()
        start = time.perf_counter()
        ids = generate(cfg, out, workers=args.workers)
        wall = time.perf_counter() - start
        after = _load()
        info = json.loads((out / "dataset.json").read_text())
    console = Console(width=150)
    console.print(
        f"full run: {len(tasks)} tasks, {len(ids)} episodes, "
        f"{'--preset paper' if args.preset else f'per-level {args.per_level}'}, "
        f"{args.workers} workers, views {args.views}, {cfg.size} px: {wall:.1f} s wall "
        f"(load average 1/5/15 min before: {before}; after: {after})"
    )
    tries = info.get("generator", {}).get("tries", {})
    if not tries:
        console.print("(this version records no tries per level)")
        return
    table = Table(title="tries per episode to meet the level's milestone (mean / max)")
    table.add_column("task")
    top = max(len(v) for v in tries.values())
    for lv in range(1, top + 1):
        table.add_column(f"L{lv}", justify="right")
    for task, per in tries.items():
        cells = []
        for lv in range(1, top + 1):
            got = per.get(str(lv))
            cells.append("" if not got else f"{sum(got) / len(got):.1f} / {max(got)}")
        table.add_row(task, *cells)
    console.print(table)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tasks", default=None, help="comma-separated, or 'all' (--full default)")
    ap.add_argument("--episodes", type=int, default=4)
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--views", default="left,wrist")
    ap.add_argument("--size", type=int, default=0, help="px (default 128; --full: 256)")
    ap.add_argument("--full", action="store_true", help="time one whole generate run")
    ap.add_argument("--per-level", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--keep", default=None, help="--full: write the dataset here (kept)")
    ap.add_argument(
        "--preset",
        choices=["paper"],
        default=None,
        help="--full: the paper preset's tasks that exist and Table 5's counts (not --tasks)",
    )
    args = ap.parse_args()
    if args.preset and not args.full:
        ap.error("--preset goes with --full")
    if args.preset and args.tasks:
        ap.error("--preset sets the tasks itself; leave out --tasks")
    if args.full:
        args.tasks = args.tasks or "all"
        full_run(args)
        return
    args.tasks = args.tasks or "Lift,PickPlaceCan"
    args.size = args.size or 128
    views = args.views.split(",")
    table = Table(
        title=f"rover generate: {args.frames} frames x {len(views)} views, "
        f"{args.size} px, one process"
    )
    for col in (
        "task",
        "s/ep",
        "CPU s/ep",
        "ep/min",
        "fps",
        "steps/ep",
        "phys steps/s",
        "phys-only ep/min",
        "render-only fps",
    ):
        table.add_column(col, justify="right")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        for name in args.tasks.split(","):
            cfg = GenerateConfig(
                tasks=[name],
                per_level=args.episodes,
                levels=["all"],
                frames=args.frames,
                views=views,
                size=args.size,
                demos=2,
            )
            make_demos(name, cfg, out / "demos")
            items = work_items(cfg)
            rng = np.random.default_rng(0)
            picked = [items[i] for i in rng.choice(len(items), args.episodes + 1, replace=False)]
            generate_episode(picked[0], cfg, out)  # warm-up
            steps = 0
            wall = cpu = 0.0
            for it in picked[1:]:
                w, c = _timed(lambda it=it, cfg=cfg: generate_episode(it, cfg, out))
                wall, cpu = wall + w, cpu + c
                from rover.io.dataset import read_episode

                steps += read_episode(out, it.episode_id, load_frames=False).extra["steps"]
            n = args.episodes
            ts = _task_state(get_task(name), cfg, out / "demos")
            sim = ts.sim
            sim.reset(0)
            act = np.zeros(len(sim.action_low))
            w, _ = _timed(lambda sim=sim, act=act: [sim.step(act) for _ in range(100)])
            phys = 100 / w
            states = ts.demos[0][0][:: max(1, len(ts.demos[0][0]) // args.frames)][: args.frames]
            w, _ = _timed(lambda ts=ts, states=states: ts.renderer.render(states, views))
            rfps = len(states) * len(views) / w
            per_ep = steps / n
            table.add_row(
                name,
                f"{wall / n:.2f}",
                f"{cpu / n:.2f}",
                f"{60 * n / wall:.1f}",
                f"{n * args.frames * len(views) / wall:.0f}",
                f"{per_ep:.0f}",
                f"{phys:.0f}",
                f"{60 * phys / per_ep:.0f}",
                f"{rfps:.0f}",
            )
    Console(width=150).print(table)
    Console().print(
        "s/ep, CPU s/ep, ep/min, fps: full pipeline (wall, CPU of all threads, episodes per "
        "minute, rendered frames per second); steps/ep: recorded control steps per episode. "
        "physics-only ep/min: every recorded step simulated, nothing rendered (an upper "
        "bound: expert segments are restored states, not simulated); render-only fps: "
        "saved states rendered, no simulation."
    )


if __name__ == "__main__":
    main()
