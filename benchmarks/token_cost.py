"""Tokens and VLM calls per video for every VLM method (paper App. G), with the oracle.

    python benchmarks/token_cost.py [--frames 30 60 120 240] [--json PATH] [--parse-only]

Each method runs on a synthetic two-subtask pick-and-place episode (256 px frames, known
subtask structure) with the oracle backend, so ROVER decomposes exactly as a model
following the prompts would; token counts use the Gemini image rule (258 tokens per
256 px frame) and tiktoken for text, as the paper's cost tables do for Gemini. It also
measures the framework's own time per call (building prompts, encoding images, parsing,
recording), excluding the time spent inside the backend.

Targets checked (App. G): ROVER <= 1/3 of GVL's tokens at 30 frames, <= 1/5 at 60,
<= 1/15 at 240; ROVER tokens(240) / tokens(30) <= 9 (linear scaling); calls per video
<= 1.25 x frames; framework overhead <= 5 ms per call.

A second table (issue 14) shows how much of each method's prompt tokens repeat an earlier
call's prompt of the same video as a prefix — what a prompt-prefix cache can serve —
measured from the request messages as sent (`rover.vlm.prefix`): the ideal share, and
what vLLM's automatic prefix caching (whole 16-token blocks) and OpenAI's prompt caching
(from 1,024 tokens, in steps of 128) can reuse of it. Its cached / uncached columns come
from the trace's totals and the cost rows, as in a real run, with a stand-in provider
that reports the vLLM-cacheable part as `cached_tokens`. Target: ROVER's repeated-prefix
share >= 40% at 30 frames.

A third table times reply parsing on 100 KB of adversarial and realistic text (issue 15:
parsing must be linear in reply length): `parse_step` under 50 ms on every input.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import random
import sys
import time
from pathlib import Path

import numpy as np

from rover.episode import Episode, Event, FrameFacts, GroundTruth, ObjectFacts, StateType, Subtask
from rover.eval.cost import cost_row
from rover.methods import get_method
from rover.methods.parse import parse_frames, parse_step
from rover.methods.registry import NON_VLM_METHODS, method_names
from rover.vlm.config import BackendConfig
from rover.vlm.oracle import OracleBackend
from rover.vlm.prefix import PrefixTracker, openai_cached, vllm_cached

SIZE = 256


def synthetic_episode(n: int, size: int = SIZE) -> Episode:
    """Pick the can, place it in the bin: n frames, two subtasks split at 45% of the video."""
    split = max(1, int(round(0.45 * (n - 1))))
    yy, xx = np.mgrid[0:size, 0:size]
    base = np.stack([xx * 0.4, yy * 0.4, np.full_like(xx, 60.0)], axis=-1).astype(np.uint8)
    frames = np.repeat(base[None], n, axis=0)
    facts, progress = [], []
    for t in range(n):
        x = int((size - 40) * t / max(n - 1, 1))
        frames[t, 100:140, x : x + 40] = (230, (t * 13) % 255, 40)
        holding = split < t < n - 1
        can = ObjectFacts(lifted=holding, inside="bin 2" if t == n - 1 else None, on=None)
        facts.append(
            FrameFacts(
                gripper="closed" if holding else "open",
                contacts=["can"] if holding else [],
                holding="can" if holding else None,
                objects={"can": can if t else can.model_copy(update={"on": "table"})},
            )
        )
        progress.append(t / (n - 1))
    return Episode(
        id=f"pick_place_{n}",
        task="pick the can and place it in the bin",
        task_group="pick_and_place",
        source="benchmark",
        frame_indices=list(range(n)),
        view_names=["agentview"],
        truth=GroundTruth(
            progress=progress,
            state_type=[StateType.expert] * n,
            subtasks=[
                Subtask(name="grasp the can", start=0, end=split, object="can"),
                Subtask(name="place the can in bin 2", start=split + 1, end=n - 1, object="can"),
            ],
            events=[Event(name="grasp", object="can", frame=split + 1)],
            facts=facts,
        ),
        views={"agentview": frames},
    )


class TimedVLM:
    """Wraps a VLM and adds up the time spent inside `complete` (the backend's share)."""

    def __init__(self, inner) -> None:
        self.inner = inner
        self.backend, self.model = inner.backend, inner.model
        self.backend_s = 0.0
        self.image_encoding = getattr(inner, "image_encoding", None)

    def bind(self, episode: Episode) -> TimedVLM:
        bound = TimedVLM(self.inner.bind(episode))
        self._bound = bound
        return bound

    async def complete(self, prompt, params=None):
        t0 = time.perf_counter()
        try:
            return await self.inner.complete(prompt, params)
        finally:
            self.backend_s += time.perf_counter() - t0


class PrefixCacheVLM:
    """Stands in for a provider with a prompt-prefix cache: measures each prompt's repeated
    prefix (one tracker per video) and reports vLLM's cacheable part as cached tokens."""

    def __init__(self, inner, tracker: PrefixTracker | None = None) -> None:
        self.inner = inner
        self.backend, self.model = inner.backend, inner.model
        self.image_encoding = getattr(inner, "image_encoding", None)
        self.tracker = tracker or PrefixTracker("gemini")
        self.openai_tokens = 0

    def bind(self, episode: Episode) -> PrefixCacheVLM:
        bound = PrefixCacheVLM(self.inner.bind(episode), PrefixTracker(self.tracker.rule))
        self._bound = bound
        return bound

    async def complete(self, prompt, params=None):
        repeated, _ = self.tracker.add(prompt)
        self.openai_tokens += openai_cached(repeated)
        out = await self.inner.complete(prompt, params)
        cached = min(vllm_cached(repeated), out.usage.prompt_tokens)
        usage = out.usage.model_copy(update={"cached_prompt_tokens": cached})
        return out.model_copy(update={"usage": usage})


def measure(method: str, n: int) -> dict:
    ep = synthetic_episode(n)
    cache = PrefixCacheVLM(OracleBackend(BackendConfig(no_cache=True)))
    vlm = TimedVLM(cache)
    m = get_method(method, concurrency=1)
    t0 = time.perf_counter()
    trace = asyncio.run(m.run(ep, vlm))
    wall = time.perf_counter() - t0
    backend_s = vlm._bound.backend_s
    t = trace.totals
    tracker = cache._bound.tracker
    cost = cost_row(trace)
    prefix = {
        "prefix_prompt_tokens": tracker.prompt_tokens,  # as measured from the messages
        "repeated_prefix_tokens": tracker.repeated_tokens,
        "repeated_share": round(tracker.share, 4),
        "vllm_cacheable_share": round(
            cost["cached_prompt_tokens"] / max(tracker.prompt_tokens, 1), 4
        ),
        "openai_cacheable_share": round(
            cache._bound.openai_tokens / max(tracker.prompt_tokens, 1), 4
        ),
        "cached_prompt_tokens": cost["cached_prompt_tokens"],
        "uncached_prompt_tokens": cost["uncached_prompt_tokens"],
    }
    return {
        "method": method,
        "frames": n,
        "prompt_tokens": t.prompt_tokens,
        "completion_tokens": t.completion_tokens,
        "total_tokens": t.total_tokens,
        "calls": t.calls,
        "wall_s": round(wall, 3),
        "overhead_ms_per_call": round(1000 * (wall - backend_s) / max(t.calls, 1), 3),
        **prefix,
    }


def print_prefix_rows(rows: list[dict]) -> None:
    print(
        f"\n{'repeated prefix':<20}{'frames':>7}{'prompt':>12}{'repeated':>12}{'share':>8}"
        f"{'vLLM':>7}{'OpenAI':>8}{'cached':>12}{'uncached':>12}"
    )
    for r in rows:
        print(
            f"{r['method']:<20}{r['frames']:>7}{r['prefix_prompt_tokens']:>12,}"
            f"{r['repeated_prefix_tokens']:>12,}{r['repeated_share']:>8.1%}"
            f"{r['vllm_cacheable_share']:>7.1%}{r['openai_cacheable_share']:>8.1%}"
            f"{r['cached_prompt_tokens']:>12,}{r['uncached_prompt_tokens']:>12,}"
        )


PARSE_BYTES = 100_000


def parse_inputs(size: int = PARSE_BYTES) -> dict[str, str]:
    """Texts of `size` characters that used to make the parsers quadratic, and real ones."""
    rng = random.Random(0)
    block = (
        "**Frame {k}:**\n- **Frame description:** The gripper is closed around the can; "
        "the robot needs to lift it next.\n- **Task completion percentage:** {p}%\n\n"
    )
    gvl = "".join(block.format(k=k, p=k % 100) for k in range(1, 2000))
    printable = "".join(rng.choice("abc xyz:%[]{}|#*-\n0123456789.") for _ in range(size))
    texts = {
        "newlines": "\n" * size,
        "spaces": " " * size,
        "short lines": "a\n" * (size // 2),
        "one digit run": "1" * size,
        "open braces": "{" * size,
        "open brackets": "[ " * (size // 2),
        "labels on one line": "Frame description: x. " * (size // 22),
        "percentages": "Subtask completion percentage: 1% " * (size // 34),
        "frame headers": "Frame 1: 1%\n" * (size // 12),
        "plan items": "New subtasks: ['" + "a', '" * (size // 5),
        "random symbols": printable,
        "GVL reply, markdown": gvl,
    }
    return {name: (t * (size // max(len(t), 1) + 1))[:size] for name, t in texts.items()}


def parse_rows(repeat: int = 5) -> list[dict]:
    """Best-of-`repeat` CPU milliseconds for parse_step and parse_frames on each input.

    CPU time (`time.process_time`), not wall time: on a shared machine the wall clock
    also counts the time other processes held the core.
    """
    rows = []
    for name, t in parse_inputs().items():
        row = {"input": name, "chars": len(t)}
        for fn in (parse_step, parse_frames):
            best = float("inf")
            for _ in range(repeat):
                t0 = time.process_time()
                fn(t)
                best = min(best, time.process_time() - t0)
            row[fn.__name__ + "_ms"] = round(1000 * best, 2)
        rows.append(row)
    return rows


def print_parse_rows(rows: list[dict]) -> None:
    print(f"\n{'reply (100 KB), CPU ms':<22}{'parse_step':>15}{'parse_frames':>17}")
    for r in rows:
        print(f"{r['input']:<22}{r['parse_step_ms']:>15.2f}{r['parse_frames_ms']:>17.2f}")


def check_targets(rows: list[dict]) -> list[tuple[str, float, float, bool]]:
    tok = {(r["method"], r["frames"]): r["total_tokens"] for r in rows}
    out = []
    for n, limit in ((30, 1 / 3), (60, 1 / 5), (240, 1 / 15)):
        if ("rover", n) in tok and ("gvl", n) in tok:
            ratio = tok[("rover", n)] / tok[("gvl", n)]
            out.append((f"ROVER/GVL tokens at {n} frames", ratio, limit, ratio <= limit))
    if ("rover", 30) in tok and ("rover", 240) in tok:
        ratio = tok[("rover", 240)] / tok[("rover", 30)]
        out.append(("ROVER tokens(240)/tokens(30)", ratio, 9.0, ratio <= 9.0))
    for r in rows:
        if r["method"].startswith("rover"):
            per = r["calls"] / r["frames"]
            out.append((f"{r['method']} calls/frame at {r['frames']}", per, 1.25, per <= 1.25))
    for r in rows:
        if r["method"] == "rover" and r["frames"] == 30:
            share = r["repeated_share"]
            out.append(("ROVER repeated-prefix share at 30 frames", share, 0.40, share >= 0.40))
    worst = max((r["overhead_ms_per_call"] for r in rows if r["method"] == "rover"), default=0)
    out.append(("ROVER framework overhead ms/call (worst)", worst, 5.0, worst <= 5.0))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", type=int, nargs="+", default=[30, 60, 120, 240])
    ap.add_argument("--methods", nargs="+", default=None, help="default: every VLM method")
    ap.add_argument("--json", type=Path, default=None, help="also write the rows as JSON")
    ap.add_argument("--parse-only", action="store_true", help="only the parsing table")
    args = ap.parse_args(argv)
    if args.parse_only:
        prows = parse_rows()
        print_parse_rows(prows)
        worst = max(r["parse_step_ms"] for r in prows)
        verdict = "PASS" if worst <= 50 else "FAIL"
        print(f"\n  {verdict}  parse_step worst on 100 KB: {worst:.1f} ms (limit 50)")
        return 0
    methods = args.methods or [m for m in method_names() if m not in NON_VLM_METHODS]
    measure("rover", 8)  # warm-up: imports, tokenizer load
    rows = []
    head = f"{'method':<20}{'frames':>7}{'prompt':>12}{'completion':>12}{'total':>12}"
    print(head + f"{'calls':>7}{'ms/call':>9}{'wall s':>8}")
    for n in args.frames:
        for method in methods:
            r = measure(method, n)
            rows.append(r)
            print(
                f"{r['method']:<20}{n:>7}{r['prompt_tokens']:>12,}{r['completion_tokens']:>12,}"
                f"{r['total_tokens']:>12,}{r['calls']:>7}{r['overhead_ms_per_call']:>9.2f}"
                f"{r['wall_s']:>8.2f}",
                flush=True,
            )
    print_prefix_rows(rows)
    prows = parse_rows()
    print_parse_rows(prows)
    targets = check_targets(rows)
    worst = max(r["parse_step_ms"] for r in prows)
    targets.append(("parse_step on 100 KB, worst input (ms)", worst, 50.0, worst <= 50.0))
    print("\ntargets")
    for name, value, limit, ok in targets:
        print(f"  {'PASS' if ok else 'FAIL'}  {name}: {value:.3f} (limit {limit:.3f})")
    if args.json:
        payload = {
            "rows": rows,
            "parse": prows,
            "targets": [
                {"name": n, "value": v, "limit": lim, "pass": ok} for n, v, lim, ok in targets
            ],
        }
        args.json.write_text(json.dumps(payload, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
