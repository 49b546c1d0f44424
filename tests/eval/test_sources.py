"""`rover eval --source`: real-video inputs, frame number as truth, one row per dataset."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
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
    from rover.vlm.testing import OpenAICompatServer

    a, b = tmp_path / "bridge.mp4", tmp_path / "kuka.mp4"
    write_video(a, make_frames(9, size=32, seed=1), fps=5)
    write_video(b, make_frames(7, size=32, seed=2), fps=5)
    out = tmp_path / "run"
    base = ["eval", "--source", f"{a},{b}", "--methods", "gvl,rover", "--out", str(out)]
    # videos carry no task: refused before any call
    res = runner.invoke(app, [*base, "--backend", "openai:m@http://127.0.0.1:9/v1"])
    assert res.exit_code != 0 and "pass --task" in str(res.exception)
    with OpenAICompatServer() as server:
        server.answer = _io_factories().model_like_answer
        spec = f"openai:test-model@{server.base_url}"
        args = [*base, "--task", "push the block", "--backend", spec, "--no-cache"]
        res = runner.invoke(app, args, catch_exceptions=False)
    assert res.exit_code == 0, res.output
    m = json.loads((out / "metrics.json").read_text())
    assert {r["dataset"] for r in m["per_trace"]} == {"bridge", "kuka"}
    assert all(r["progress_source"] == "frame_number" for r in m["per_trace"])
    # no simulator facts: Task 2 rates are undefined, not a perfect 0% error rate
    assert all(r["error_rate"] is None and r["err_perception"] is None for r in m["per_trace"])
    rows = [x for x in m["aggregates"] if x["by"] == "dataset" and x["metric"] == "voc"]
    assert {x["group"] for x in rows} == {"bridge", "kuka"}
    assert "App. L: VOC by dataset" in (out / "summary.md").read_text()
    run = json.loads((out / "run.json").read_text())
    assert run["dataset"] is None and len(run["sources"]) == 2


def test_oracle_is_refused_on_frame_number_truth(tmp_path: Path) -> None:
    """The oracle would echo frame-number truth back as r = 1.00: refused before any work."""
    a = tmp_path / "bridge.mp4"
    write_video(a, make_frames(6, size=32, seed=1), fps=5)
    out = tmp_path / "run"
    args = ["eval", "--source", str(a), "--task", "push", "--methods", "gvl", "--out", str(out)]
    res = runner.invoke(app, [*args, "--backend", "oracle"])
    assert res.exit_code != 0
    assert "the oracle answers from simulator ground truth" in str(res.exception)
    assert not out.exists()  # nothing written, no unit started


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
                "--backend",
                "oracle",
                "--out",
                str(out),
            ],
            catch_exceptions=False,
        )
        assert res.exit_code == 0, res.output
        picked.append(json.loads((out / "run.json").read_text())["episodes"])
    assert picked[0] == picked[1] and len(picked[0]) == 2


def _io_factories():
    """The sources engineer's dataset writers (tests/io/conftest.py), loaded by path."""
    import importlib.util

    path = Path(__file__).parents[1] / "io" / "conftest.py"
    spec = importlib.util.spec_from_file_location("rover_io_test_factories", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_openx_style_sources_one_row_each(tmp_path: Path) -> None:
    """App. L on real formats: a LeRobot v2 dataset and an RLDS folder side by side."""
    pytest.importorskip("pyarrow")
    io_f = _io_factories()
    lerobot = io_f.write_lerobot_v2(tmp_path / "lerobot_toy", lengths=(8, 7, 9))
    rlds = io_f.write_rlds(tmp_path / "rlds_toy", shards=((8, 6), (7,)), name="rlds_toy")
    out = tmp_path / "run"
    from rover.vlm.testing import OpenAICompatServer

    with OpenAICompatServer() as server:
        server.answer = io_f.model_like_answer
        res = runner.invoke(
            app,
            [
                "eval",
                "--source",
                f"lerobot:{lerobot},rlds:{rlds}",
                "--episodes",
                "2",
                "--seed",
                "0",
                "--methods",
                "gvl",
                "--backend",
                f"openai:test-model@{server.base_url}",
                "--no-cache",
                "--out",
                str(out),
            ],
            catch_exceptions=False,
        )
    assert res.exit_code == 0, res.output
    m = json.loads((out / "metrics.json").read_text())
    assert m["counts"]["failed"] == 0 and m["counts"]["traces"] == 4
    assert {r["dataset"] for r in m["per_trace"]} == {"lerobot_toy", "rlds_toy"}
    assert all(r["progress_source"] == "frame_number" for r in m["per_trace"])
    rows = {x["group"]: x for x in m["aggregates"] if x["by"] == "dataset" and x["metric"] == "voc"}
    assert set(rows) == {"lerobot_toy", "rlds_toy"} and all(x["n"] == 2 for x in rows.values())
