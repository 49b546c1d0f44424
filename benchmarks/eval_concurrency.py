"""Does `rover eval` overlap episodes? 32 episodes at --concurrency 32 vs one at a time.

A VLM that sleeps 0.5 s per call stands in for a remote API. If nothing blocks the event
loop (video decoding and file writes go through threads), 32 concurrent episodes finish
in about the time of the slowest single episode. Target: ratio <= 1.2.

Two methods: ROVER (one call at a time per episode, the paper's main method) and
TemporalConcat (its per-frame calls already run 8 at a time inside one episode, so a single
episode is short and the decoding of all 32 videos up front weighs more). The episodes are
statistically identical, so `--singles` of them are timed alone (default 4).

    python benchmarks/eval_concurrency.py [--episodes 32] [--frames 30] [--delay 0.5]
"""

from __future__ import annotations

import argparse
import asyncio
import tempfile
import time
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from rover.episode import Episode, GroundTruth
from rover.eval.runner import EvalOptions, prepare_run
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode
from rover.vlm.types import Completion, Prompt, SamplingParams, Usage


class SleepyVLM:
    """Answers every prompt after `delay` seconds, like a slow remote API would."""

    backend = "sleepy"
    model = "sleep"

    def __init__(self, delay: float) -> None:
        self.delay = delay
        self.calls = 0

    def bind(self, episode: Episode) -> SleepyVLM:
        return self

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        await asyncio.sleep(self.delay)
        self.calls += 1
        pct = min(100, 5 * len(prompt.images()))
        text = f"Frame description: The gripper is open.\nTask completion percentage: {pct}%"
        return Completion(
            text=text,
            usage=Usage(prompt_tokens=100, completion_tokens=20),
            latency_s=self.delay,
            backend=self.backend,
            model=self.model,
        )


def smooth_frames(n: int, size: int, seed: int) -> np.ndarray:
    """A gradient scene with a moving square: compresses like real video, unlike noise."""
    ramp = np.linspace(0, 160, size, dtype=np.float32)
    base = np.zeros((size, size, 3), dtype=np.uint8)
    base[..., 0], base[..., 1] = ramp[None, :], ramp[:, None]
    base[..., 2] = (seed * 37) % 200
    frames = np.repeat(base[None], n, axis=0)
    side = size // 6
    for t in range(n):
        x = int((size - side) * t / max(n - 1, 1))
        frames[t, size // 3 : size // 3 + side, x : x + side] = (240, 60, 40)
    return frames


def make_dataset(root: Path, n: int, frames: int, size: int = 128) -> None:
    write_dataset_info(root, DatasetInfo(name="bench", views=["rgb"]))
    for i in range(n):
        ep = Episode(
            id=f"ep{i:02d}",
            task="pick up the can",
            frame_indices=list(range(frames)),
            view_names=["rgb"],
            views={"rgb": smooth_frames(frames, size, i)},
            truth=GroundTruth(progress=[t / (frames - 1) for t in range(frames)]),
        )
        write_episode(root, ep)


async def timed_run(
    ds: Path,
    out: Path,
    vlm: SleepyVLM,
    concurrency: int,
    method: str,
    episode: str | None = None,
) -> float:
    """Wall time of the runner's work (not of setup or the final metrics)."""
    opts = EvalOptions(
        dataset=ds,
        methods=[method],
        backends=["sleepy"],
        judge="rule",
        answerer="rule",
        concurrency=concurrency,
        out=out,
    )
    runner = await asyncio.to_thread(prepare_run, opts, None, {"sleepy": vlm})
    if episode is not None:
        runner.refs = [r for r in runner.refs if r.id == episode]
    start = time.perf_counter()
    await runner.run()
    return time.perf_counter() - start


class LoopWatch:
    """Measures the event loop's longest stall: a 5 ms heartbeat and how late it wakes."""

    def __init__(self) -> None:
        self.worst = 0.0
        self._task: asyncio.Task | None = None

    async def _beat(self) -> None:
        while True:
            t = time.perf_counter()
            await asyncio.sleep(0.005)
            self.worst = max(self.worst, time.perf_counter() - t - 0.005)

    def __enter__(self) -> LoopWatch:
        self._task = asyncio.get_running_loop().create_task(self._beat())
        return self

    def __exit__(self, *exc: object) -> None:
        if self._task is not None:
            self._task.cancel()


async def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=32)
    ap.add_argument("--concurrency", type=int, default=32)
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--delay", type=float, default=0.5)
    ap.add_argument("--methods", default="rover,temporal-concat")
    ap.add_argument("--singles", type=int, default=4, help="episodes timed alone")
    args = ap.parse_args()
    table = Table(
        title=f"rover eval: episode concurrency ({args.frames} frames, "
        f"{args.delay:g} s per VLM call)"
    )
    for col in (
        "method",
        "episodes",
        "concurrency",
        "calls",
        "wall time (s)",
        "slowest single (s)",
        "ratio",
        "target <= 1.2",
        "longest loop stall (ms)",
    ):
        table.add_column(col, justify="right")
    with tempfile.TemporaryDirectory() as tmp:
        ds = Path(tmp) / "ds"
        make_dataset(ds, args.episodes, args.frames)
        for method in args.methods.split(","):
            singles = []
            for i in range(min(args.singles, args.episodes)):
                eid = f"ep{i:02d}"
                out = Path(tmp) / f"{method}-one-{eid}"
                singles.append(await timed_run(ds, out, SleepyVLM(args.delay), 1, method, eid))
            vlm = SleepyVLM(args.delay)
            out = Path(tmp) / f"{method}-all"
            with LoopWatch() as watch:
                wall = await timed_run(ds, out, vlm, args.concurrency, method)
            slowest = max(singles)
            ratio = wall / slowest
            table.add_row(
                method,
                str(args.episodes),
                str(args.concurrency),
                str(vlm.calls),
                f"{wall:.2f}",
                f"{slowest:.2f}",
                f"{ratio:.2f}",
                "ok" if ratio <= 1.2 else "MISSED",
                f"{1000 * watch.worst:.0f}",
            )
    Console(width=150).print(table)


if __name__ == "__main__":
    asyncio.run(main())
