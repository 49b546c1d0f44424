"""`rover demo`: every VLM method through the real runner, oracle backend, then the report."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

import rover.sim
from rover.cli import app
from rover.commands.demo import demo_methods


def _check_demo_output(out: Path, output: str, episodes: int) -> None:
    index = out / "report" / "index.html"
    assert index.exists()
    assert str(index) in output
    assert "ORACLE OUTPUT" in output
    page = index.read_text()
    assert 'id="oracle-banner"' in page
    run = json.loads((out / "run" / "run.json").read_text())
    assert run["backends"] == ["oracle"]
    traces = list((out / "run" / "traces").rglob("*.json"))
    assert len(traces) == episodes * len(demo_methods())
    for name in ("ROVER", "GVL", "TemporalConcat", "LocalConcat", "VideoConcat"):
        assert name in output and name in page
    assert (out / "report" / "figures" / "pearson_by_group_level.png").exists()


def test_demo_on_a_small_dataset(make_run, monkeypatch, tmp_path: Path) -> None:
    """The demo's own logic on a 3-episode dataset standing in for the bundled one."""
    dataset = make_run().parent.parent / "dataset"
    monkeypatch.setattr(rover.sim, "bundled_dataset_path", lambda: dataset)
    out = tmp_path / "demo"
    result = CliRunner().invoke(app, ["demo", "--out", str(out)])
    assert result.exit_code == 0, result.output
    _check_demo_output(out, result.output, episodes=3)
    # a second run resumes: finished traces are kept, nothing is redone
    before = {p: p.stat().st_mtime_ns for p in (out / "run" / "traces").rglob("*.json")}
    again = CliRunner().invoke(app, ["demo", "--out", str(out)])
    assert again.exit_code == 0, again.output
    assert {p: p.stat().st_mtime_ns for p in before} == before


def test_demo_rejects_unknown_methods(tmp_path: Path) -> None:
    result = CliRunner().invoke(app, ["demo", "--out", str(tmp_path), "--methods", "nope"])
    assert result.exit_code != 0


@pytest.mark.slow
@pytest.mark.skipif(
    not (rover.sim.bundled_dataset_path() / "dataset.json").exists(),
    reason="bundled dataset not built yet",
)
def test_demo_end_to_end_on_the_bundled_dataset(tmp_path: Path) -> None:
    from rover.io.dataset import episode_ids

    out = tmp_path / "demo"
    result = CliRunner().invoke(app, ["demo", "--out", str(out)])
    assert result.exit_code == 0, result.output
    episodes = len(episode_ids(rover.sim.bundled_dataset_path()))
    _check_demo_output(out, result.output, episodes=episodes)
