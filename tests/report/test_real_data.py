"""`rover report` on a real-data run: a LeRobot dataset, a chat-style scripted model.

Real videos carry no simulator facts and no measured progress; the report must still
show the summary, Pearson / VOC against frame-number truth, the App. L per-dataset
table, filmstrips and reasoning trees, and say in one line which analyses do not apply
(never 0.00 ± 0.00 from all-inconclusive verdicts, never "reasoning error 100%").
"""

from __future__ import annotations

import importlib.util
import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rover.cli import app

pytest.importorskip("pyarrow")
runner = CliRunner()


def io_factories():
    """The sources engineer's dataset writers (tests/io/conftest.py), loaded by path."""
    path = Path(__file__).parents[1] / "io" / "conftest.py"
    spec = importlib.util.spec_from_file_location("rover_io_test_factories_report", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def lerobot_run(tmp_path: Path) -> Path:
    """`rover eval --source lerobot:...` with ROVER and GVL through a loopback model."""
    from rover.vlm.testing import OpenAICompatServer

    io_f = io_factories()
    lerobot = io_f.write_lerobot_v2(tmp_path / "so100_toy", lengths=(8, 7), size=48)
    out = tmp_path / "run"
    with OpenAICompatServer() as server:
        server.answer = io_f.model_like_answer
        res = runner.invoke(
            app,
            [
                "eval",
                "--source",
                f"lerobot:{lerobot}",
                "--methods",
                "rover,gvl",
                "--backend",
                f"openai:test-model@{server.base_url}",
                "--no-cache",
                "--out",
                str(out),
            ],
            catch_exceptions=False,
        )
    assert res.exit_code == 0, res.output
    return out


def test_report_on_a_lerobot_run_shows_progress_metrics_and_app_l(tmp_path: Path) -> None:
    run = lerobot_run(tmp_path)
    # the run is self-contained: move it away from the dataset and report it there
    moved = tmp_path / "elsewhere" / "run"
    moved.parent.mkdir()
    run.rename(moved)
    (tmp_path / "so100_toy").rename(tmp_path / "gone")
    res = runner.invoke(app, ["report", str(moved)], catch_exceptions=False)
    assert res.exit_code == 0, res.output
    assert "not found" not in res.output
    index = moved / "report" / "index.html"
    page = index.read_text()
    metrics = json.loads((moved / "metrics.json").read_text())
    rows = metrics["per_trace"]
    assert len(rows) == 4 and all(r["progress_source"] == "frame_number" for r in rows)
    assert all(r["pearson"] is not None and r["voc"] is not None for r in rows)
    # the summary's Pearson and VOC columns, and the App. L per-dataset table
    head = re.search(r'<table class="summary">\s*<thead><tr>(.*?)</tr>', page, re.S).group(1)
    assert "Pearson r" in head and "VOC" in head and "Error rate" not in head
    for title in ("App. L: VOC by dataset", "App. L: correlation with frame number by dataset"):
        assert title in page
    assert "so100_toy" in page
    # methods are rows (no camera name in a method label)
    labels = re.findall(r'<span class="swatch"[^>]*></span>([^<]+)</td>', page)
    assert {"ROVER", "GVL"} <= set(labels) and not any("observation" in x for x in labels)
    # inapplicable analyses: one line each, never zeros
    assert "no video in this run has simulator facts" in page
    assert "0.00 ± 0.00" not in page and "Reasoning error" not in page
    summary = (moved / "summary.md").read_text()
    assert "frames in context" not in summary.split("## Counts")[0].split("App. L")[0] or (
        "error rate % by frames in context" not in summary
    )
    # episode pages: filmstrip from the run's own frames, curves against frame number, tree
    pages = sorted((moved / "report" / "episodes").glob("*.html"))
    assert len(pages) == 2
    for p in pages:
        text = p.read_text()
        # a report inside its run points at the run's own frames (nothing copied)
        thumbs = re.findall(r'<img src="([^"]+\.jpg)"', text)
        assert thumbs and all((p.parent / t).resolve().is_file() for t in thumbs)
        assert all((p.parent / t).resolve().is_relative_to(moved / "frames") for t in thumbs)
        assert "ground truth (frame number)" in text
        assert text.count("<polyline") == 3
        assert 'class="tree"' in text  # ROVER's reasoning tree
