"""Scripted-expert success rates: how often each task's expert solves a seeded scene.

Usage: python benchmarks/expert_success.py [--seeds 20] [--suite kitchen] [--tasks Lift,Door]
       [--write]
Prints one row per task (successes / seeds, mean demo length, seconds per demo). With
--write each task's result is recorded in src/rover/sim/expert_success.json (other
tasks' records are kept), which `rover tasks` shows; run it after changing a task.
"""

from __future__ import annotations

import argparse
import time

from rich.console import Console
from rich.table import Table

from rover.sim.env import SimEnv
from rover.sim.expert_record import RECORD, write_record
from rover.sim.experts import run_expert
from rover.sim.tasks import get_task, task_names


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--suite", default="tabletop", help="tabletop, kitchen or all")
    ap.add_argument("--tasks", default=None, help="comma-separated names (default: the suite)")
    ap.add_argument("--write", action="store_true", help=f"record the results in {RECORD.name}")
    args = ap.parse_args()
    if args.seeds < 1:
        ap.error("--seeds must be at least 1")
    names = args.tasks.split(",") if args.tasks else task_names(args.suite)
    table = Table(title=f"Scripted expert success over {args.seeds} seeds")
    for col in ("task", "success", "rate", "mean steps", "s / demo"):
        table.add_column(col)
    for name in names:
        sim = SimEnv(get_task(name))
        run_expert(sim, 10_000)  # warm-up (first episode per process is slow)
        ok, steps, start = 0, 0, time.perf_counter()
        for seed in range(args.seeds):
            demo = run_expert(sim, seed)
            ok += demo.success
            steps += len(demo.actions)
        took = (time.perf_counter() - start) / args.seeds
        table.add_row(
            name,
            f"{ok}/{args.seeds}",
            f"{ok / args.seeds:.0%}",
            f"{steps / args.seeds:.0f}",
            f"{took:.2f}",
        )
        Console().print(f"{name}: {ok}/{args.seeds}")
        if args.write:
            write_record(get_task(name), ok, args.seeds, steps / args.seeds)
    Console().print(table)
    if args.write:
        Console().print(f"recorded in {RECORD}")


if __name__ == "__main__":
    main()
