"""Render cost per frame of a kitchen task vs. a tabletop task (issue 10: within 1.5x).

Usage: python benchmarks/kitchen_render_cost.py [--tabletop TurnKnob]
       [--kitchen kitchen.TurnOnStove] [--size 256] [--views left,wrist]

Renders the task's start state 30 times per view (best of three runs, after a warm-up)
and prints milliseconds per frame and the kitchen / tabletop ratio.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.render import StateRenderer
from rover.sim.tasks import get_task


def ms_per_frame(task: str, size: int, views: list[str]) -> float:
    sim = SimEnv(get_task(task))
    states = np.repeat(sim.reset(0)[None], 30, axis=0)
    renderer = StateRenderer(sim.model, size)
    try:
        renderer.render(states[:2], views)  # warm-up
        runs = []
        for _ in range(3):
            start = time.perf_counter()
            renderer.render(states, views)
            runs.append((time.perf_counter() - start) / (len(states) * len(views)))
    finally:
        renderer.close()
    return 1000 * min(runs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tabletop", default="TurnKnob")
    ap.add_argument("--kitchen", default="kitchen.TurnOnStove")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--views", default="left,wrist")
    args = ap.parse_args()
    views = args.views.split(",")
    base = ms_per_frame(args.tabletop, args.size, views)
    kitchen = ms_per_frame(args.kitchen, args.size, views)
    print(f"{args.tabletop}: {base:.1f} ms/frame")
    print(f"{args.kitchen}: {kitchen:.1f} ms/frame")
    print(f"ratio: {kitchen / base:.2f}")


if __name__ == "__main__":
    main()
