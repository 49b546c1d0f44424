"""How the report scales: a synthetic run of the paper's size (543 episodes x 8 methods).

Writes a run directory in rover eval's layout (run.json, episodes/, frames/, traces,
rule-judge verdicts, QA answers), scores it once with the real scorer, then times
`build_report` and measures what a reader downloads: the main page alone (episode
detail lives in one small page per episode beside it). Prints one table.

    python benchmarks/report_scale.py                 # 543 x 8, 30 frames
    python benchmarks/report_scale.py --episodes 60   # a quick look
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from rover.episode import Episode, FrameFacts, GroundTruth, QAItem, StateType, Subtask
from rover.eval.judge import rule_judge_trace
from rover.eval.qa import rule_answer_trace
from rover.eval.results import compute_metrics, write_results
from rover.eval.rundir import RunDir, write_json_atomic
from rover.eval.variants import expand_variants
from rover.methods.registry import vlm_method_names
from rover.methods.trace import CallRecord, FrameRecord, Trace
from rover.report import build_report
from rover.run.store import write_thumbs

METHODS = vlm_method_names()  # the paper's 8 VLM methods
GROUPS = ["pick_and_place", "open_door", "stack", "turn_knob"]


def _episode(i: int, n: int, rng: np.random.Generator) -> Episode:
    stall = int(rng.integers(n // 3, n))
    progress = [min(t, stall) / (n - 1) for t in range(n)]
    half = n // 2
    facts = [
        FrameFacts(
            gripper="closed" if half <= t else "open",
            holding="cube" if half <= t else None,
            contacts=["cube"] if half <= t else [],
        )
        for t in range(n)
    ]
    return Episode(
        id=f"ep{i:04d}",
        task="pick up the cube and place it on the plate",
        task_group=GROUPS[i % len(GROUPS)],
        source="synthetic",
        fps=10,
        frame_indices=list(range(n)),
        view_names=["agentview"],
        truth=GroundTruth(
            progress=progress,
            state_type=[StateType.expert if t <= stall else StateType.non_expert for t in range(n)],
            subtasks=[
                Subtask(name="grasp the cube", start=0, end=half - 1, object="cube"),
                Subtask(name="place the cube on the plate", start=half, end=n - 1, object="cube"),
            ],
            facts=facts,
            level=1 + i % 8,
            qa=[
                QAItem(
                    question="Did the robot pick up the cube? If so, when?",
                    answer=True,
                    frame=half,
                    template="did_pick_up",
                    event="pick_up",
                    object="cube",
                )
            ],
        ),
    )


def _trace(ep: Episode, method: str, k: int, rng: np.random.Generator) -> Trace:
    noise = 3.0 + 4.0 * k
    truth = ep.truth.progress
    frames = [
        FrameRecord(
            index=ix,
            position=pos,
            progress=float(np.clip(100 * truth[pos] + rng.normal(0, noise), 0, 100)),
            description=(
                "The gripper is closed. The robot is holding the cube."
                if pos >= ep.num_frames // 2
                else "The gripper is open. The robot is not holding anything."
            ),
            subtask_path=["grasp the cube"] if pos < ep.num_frames // 2 else ["place the cube"],
            predicted=True,
        )
        for pos, ix in enumerate(ep.frame_indices)
    ]
    calls = [
        CallRecord(id=c, kind=f"{method}.step", prompt_tokens=900, completion_tokens=40)
        for c in range(ep.num_frames)
    ]
    t = Trace(
        method=method,
        backend="synthetic",
        model="synthetic",
        episode_id=ep.id,
        task=ep.task,
        view="agentview",
        num_frames=ep.num_frames,
        frame_indices=ep.frame_indices,
        frames=frames,
        calls=calls,
    )
    t.totals = t.compute_totals()
    return t


def make_run(root: Path, episodes: int, frames: int, methods: list[str]) -> dict:
    rng = np.random.default_rng(0)
    variants = expand_variants(methods, ["synthetic"], [None], [None], [None])
    eps = [_episode(i, frames, rng) for i in range(episodes)]
    config = {
        "schema_version": 1,
        "dataset": None,
        "sources": ["synthetic"],
        "episodes": [e.id for e in eps],
        "episode_datasets": {e.id: "synthetic" for e in eps},
        "methods": methods,
        "backends": ["synthetic"],
        "judge": "rule",
        "answerer": "rule",
        "variants": [v.model_dump(mode="json") for v in variants],
    }
    rundir = RunDir(root)
    root.mkdir(parents=True, exist_ok=True)
    (root / "run.json").write_text(json.dumps(config))
    pixels = rng.integers(0, 255, (frames, 48, 48, 3), dtype=np.uint8)
    for ep in eps:
        write_json_atomic(rundir.episode_path(ep.id), ep)
        write_thumbs(root, ep.id, "agentview", pixels, ep.frame_indices)
        for k, v in enumerate(variants):
            trace = _trace(ep, v.method, k, rng)
            trace.save(rundir.trace_path(ep.id, v.id))
            write_json_atomic(
                rundir.stage_path("judge", ep.id, v.id), rule_judge_trace(trace, ep, v.id)
            )
            write_json_atomic(
                rundir.stage_path("qa", ep.id, v.id), rule_answer_trace(trace, ep, v.id)
            )
    return config


def _size(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=543)
    ap.add_argument("--methods", type=int, default=len(METHODS), help="how many of the 8")
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--out", type=Path, default=None, help="keep the run here")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = args.out or Path(tmp) / "run"
        t0 = time.perf_counter()
        config = make_run(root, args.episodes, args.frames, METHODS[: args.methods])
        t1 = time.perf_counter()
        rundir = RunDir(root)
        write_results(rundir, compute_metrics(rundir, config))
        t2 = time.perf_counter()
        index = build_report(root)
        t3 = time.perf_counter()
        pages = list((index.parent / "episodes").glob("*.html"))
        rows = [
            ("episodes x methods", f"{args.episodes} x {args.methods} ({args.frames} frames)"),
            ("write synthetic run (s)", f"{t1 - t0:.1f}"),
            ("score: metrics.json + summary.md (s)", f"{t2 - t1:.1f}"),
            ("build report (s)  [target < 60]", f"{t3 - t2:.1f}"),
            ("main page index.html (MB)  [target < 10]", f"{index.stat().st_size / 1e6:.2f}"),
            ("episode pages", f"{len(pages)}"),
            (
                "largest episode page (kB)",
                f"{max(p.stat().st_size for p in pages) / 1e3:.0f}" if pages else "-",
            ),
            ("whole report folder (MB)", f"{_size(index.parent) / 1e6:.1f}"),
        ]
        width = max(len(k) for k, _ in rows)
        print(f"{'measure':<{width}}  value")
        for k, v in rows:
            print(f"{k:<{width}}  {v}")


if __name__ == "__main__":
    main()
