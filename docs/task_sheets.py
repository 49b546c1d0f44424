"""Render one contact sheet per task for docs/generate.md: rows = views (wrist, left,
right), columns = start, middle and end of a scripted expert demonstration.

Usage: python docs/task_sheets.py [--tasks Lift,Door] [--size 128] [--out docs/images]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image

from rover.sim.env import SimEnv
from rover.sim.experts import run_expert
from rover.sim.render import VIEW_NAMES, StateRenderer
from rover.sim.tasks import get_task, task_names


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tasks", default=",".join(task_names()))
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--out", type=Path, default=Path("docs/images"))
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    for name in args.tasks.split(","):
        sim = SimEnv(get_task(name))
        demo = run_expert(sim, 0)
        n = len(demo.states)
        picked = demo.states[[0, n // 2, n - 1]]
        frames = StateRenderer(sim.model, args.size).render(picked, VIEW_NAMES)
        rows = [np.concatenate(list(frames[v]), axis=1) for v in VIEW_NAMES]
        path = args.out / f"task_{name}.png"
        Image.fromarray(np.concatenate(rows, axis=0)).save(path, optimize=True)
        print(f"{path} ({path.stat().st_size // 1024} KiB, expert success={demo.success})")


if __name__ == "__main__":
    main()
