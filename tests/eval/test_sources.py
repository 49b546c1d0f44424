"""`rover eval --source`: real-video inputs, frame number as truth, one row per dataset."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from rover.cli import app
from rover.io.video import write_video

runner = CliRunner()


def make_frames(n: int, size: int = 32, seed: int = 0) -> np.ndarray:
    """A moving bright square on a gradient: every frame distinct."""
    frames = np.zeros((n, size, size, 3), dtype=np.uint8)
    frames[..., 0] = np.linspace(0, 120, size, dtype=np.uint8)[None, None, :]
    frames[..., 2] = (seed * 37) % 200
    for t in range(n):
        x = int((size - 8) * t / max(n - 1, 1))
        frames[t, 10:18, x : x + 8] = (255, 40 + 7 * t, 40)
    return frames


def test_sources_use_frame_number_truth_and_get_per_dataset_rows(tmp_path: Path) -> None:
    a, b = tmp_path / "bridge.mp4", tmp_path / "kuka.mp4"
    write_video(a, make_frames(9, size=32, seed=1), fps=5)
    write_video(b, make_frames(7, size=32, seed=2), fps=5)
    out = tmp_path / "run"
    res = runner.invoke(
        app,
        [
            "eval",
            "--source",
            f"{a},{b}",
            "--methods",
            "gvl,rover",
            "--backend",
            "oracle",
            "--out",
            str(out),
        ],
        catch_exceptions=False,
    )
    assert res.exit_code == 0, res.output
    m = json.loads((out / "metrics.json").read_text())
    assert {r["dataset"] for r in m["per_trace"]} == {"bridge", "kuka"}
    assert all(r["progress_source"] == "frame_number" for r in m["per_trace"])
    # the oracle follows frame-number truth exactly
    assert all(r["voc"] > 0.99 for r in m["per_trace"] if r["method"] == "gvl")
    rows = [x for x in m["aggregates"] if x["by"] == "dataset" and x["metric"] == "voc"]
    assert {x["group"] for x in rows} == {"bridge", "kuka"}
    assert "App. L: VOC by dataset" in (out / "summary.md").read_text()
    run = json.loads((out / "run.json").read_text())
    assert run["dataset"] is None and run["sources"] == [str(a), str(b)]


def test_episode_sampling_is_reproducible(tmp_path: Path, make_dataset) -> None:
    ds = make_dataset(tmp_path / "ds", n=5, frames=4)
    picked = []
    for k in range(2):
        out = tmp_path / f"run{k}"
        res = runner.invoke(
            app,
            [
                "eval",
                "--source",
                str(ds),
                "--episodes",
                "2",
                "--seed",
                "3",
                "--methods",
                "gvl",
                "--out",
                str(out),
            ],
            catch_exceptions=False,
        )
        assert res.exit_code == 0, res.output
        picked.append(json.loads((out / "run.json").read_text())["episodes"])
    assert picked[0] == picked[1] and len(picked[0]) == 2
