"""The runner end to end on a tiny dataset, through the real CLI."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from rover.cli import app

runner = CliRunner()


def _eval(*args: str):
    return runner.invoke(app, ["eval", *args], catch_exceptions=False)


def test_oracle_run_end_to_end(tmp_path: Path, make_dataset) -> None:
    ds = make_dataset(tmp_path / "ds", n=3, frames=12)
    out = tmp_path / "run"
    res = _eval("--dataset", str(ds), "--methods", "rover,gvl,temporal-concat,local-concat",
                "--backend", "oracle", "--out", str(out), "--concurrency", "4")
    assert res.exit_code == 0, res.output
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["counts"]["traces"] == 12
    assert metrics["counts"]["failed"] == 0
    rows = {(r["episode_id"], r["method"]): r for r in metrics["per_trace"]}
    # the oracle answers from ground truth: near-perfect progress and reasoning
    for (eid, method), r in rows.items():
        assert r["pearson"] > 0.95, (eid, method, r["pearson"])
        assert r["error_rate"] == 0.0
    assert (out / "summary.md").read_text().startswith("# rover eval summary")
    assert len(list((out / "traces").rglob("*.json"))) == 12
