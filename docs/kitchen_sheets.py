"""Contact sheets of the kitchen suite: two random scenes per task, start / middle / end.

Usage: python docs/kitchen_sheets.py [--tasks kitchen.OpenDrawer,...] [--seeds 0,1]
       [--size 160] [--out docs/images] [--at-ends]

For each task and seed it runs the scripted expert in that seed's kitchen and renders
the first, middle and last state of the demonstration from the ``left`` and ``wrist``
views (``--at-ends``: the first state, the state at each subtask's end and the last, so a
composite task's sheet shows every component done); ``kitchen_<Task>.png`` has one row
per (seed, view). The scene of each seed
(fixture layout, textures, light, camera) is printed so a sheet can be checked against it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

VIEWS = ("left", "wrist")


def _label(img: np.ndarray, text: str) -> np.ndarray:
    pic = Image.fromarray(img)
    ImageDraw.Draw(pic).text((3, 2), text, fill=(255, 255, 0))
    return np.asarray(pic)


def sheet(
    task: str, seeds: list[int], size: int, at_ends: bool = False
) -> tuple[np.ndarray, list[str]]:
    from rover.sim.env import SimEnv
    from rover.sim.experts import run_expert
    from rover.sim.render import StateRenderer
    from rover.sim.tasks import get_task

    sim = SimEnv(get_task(task))
    renderer = StateRenderer(sim.model, size)
    rows, notes = [], []
    try:
        for seed in seeds:
            demo = run_expert(sim, seed)
            sim.reset(seed)  # the seed's scene on the model again
            scene = sim.env.scene.to_json()
            notes.append(f"{task} seed {seed}: success={demo.success} {scene['textures']}")
            n = len(demo.states)
            picks = [0, n // 2, n - 1]
            if at_ends:
                picks = sorted({0, *(int(e) for e in demo.subtask_ends), n - 1})
            frames = renderer.render(demo.states[picks], list(VIEWS))
            for view in VIEWS:
                cells = [
                    _label(frames[view][k], f"seed {seed} {view} t={t}/{n - 1}")
                    for k, t in enumerate(picks)
                ]
                rows.append(np.concatenate(cells, axis=1))
    finally:
        renderer.close()
    return np.concatenate(rows, axis=0), notes


def main() -> None:
    from rover.sim.tasks import task_names

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tasks", default=None, help="comma-separated (default: the kitchen suite)")
    ap.add_argument("--seeds", default="0,1")
    ap.add_argument("--size", type=int, default=160)
    ap.add_argument("--out", type=Path, default=Path("docs/images"))
    ap.add_argument("--at-ends", action="store_true", help="frames at every subtask's end")
    args = ap.parse_args()
    tasks = args.tasks.split(",") if args.tasks else task_names("kitchen")
    seeds = [int(s) for s in args.seeds.split(",")]
    args.out.mkdir(parents=True, exist_ok=True)
    for task in tasks:
        img, notes = sheet(task, seeds, args.size, args.at_ends)
        path = args.out / f"kitchen_{task.removeprefix('kitchen.')}.png"
        Image.fromarray(img).save(path, optimize=True)
        print(path, *notes, sep="\n  ")


if __name__ == "__main__":
    main()
