"""The report: figures on disk, escaping of model text, oracle labelling, the CLI."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from markupsafe import escape
from PIL import Image
from typer.testing import CliRunner

from rover.cli import app
from rover.errors import InputError
from rover.eval.progress_metrics import score_progress
from rover.io.dataset import read_episode
from rover.methods.trace import Trace
from rover.report import build_report


def test_oracle_report(make_run, tmp_path: Path) -> None:
    """One report, many checks: building it is the slow part (matplotlib)."""
    run = make_run()
    index = build_report(run, tmp_path / "report")
    page = index.read_text()
    _check_figures(index, page)
    _check_escaping(page)
    _check_oracle_labels(page)
    _check_viewer(index, page)
    _check_summary(run, page)


def _check_figures(index: Path, page: str) -> None:
    figures = sorted((index.parent / "figures").iterdir())
    stems = {p.stem for p in figures}
    # progress, reasoning, QA, temporal distance, frame-number correlation, cost
    for name in (
        "pearson_by_group_level",
        "l2_by_group_level",
        "error_rate_by_group_level",
        "success_rate_by_group_level",
        "qa_accuracy_by_group_level",
        "qa_temporal_distance",
        "frame_corr_by_non_expert",
        "cost_tokens",
    ):
        assert name in stems, name
    for stem in stems:
        png, svg = (
            index.parent / "figures" / f"{stem}.png",
            index.parent / "figures" / f"{stem}.svg",
        )
        assert png.stat().st_size > 1000 and svg.stat().st_size > 1000
        with Image.open(png) as im:
            im.load()
            assert im.size[0] > 300 and im.size[1] > 150
        assert svg.read_text().lstrip().startswith("<?xml") and "</svg>" in svg.read_text()
    for stem in stems:
        assert f"figures/{stem}.svg" in page


def _check_escaping(page: str) -> None:
    assert "<script" not in page.lower()
    assert str(escape("<script>document.title='pwned'</script>")) in page
    # subtasks in the reasoning tree are model text too
    assert "grasp the &lt;b&gt;can&lt;/b&gt;" in page
    assert "plan: grasp the &lt;b&gt;can&lt;/b&gt; → place the can in the bin" in page


def _check_oracle_labels(page: str) -> None:
    assert 'id="oracle-banner"' in page
    assert "ORACLE OUTPUT — answers come from simulator ground truth, not a VLM" in page
    assert "oracle:oracle" in page  # the backend is named
    # every section and every method in the viewer carries the label
    assert page.count('class="badge oracle"') >= 4 + 3 * 3


def test_report_command_without_oracle(make_run, tmp_path: Path) -> None:
    """`rover report` on a non-oracle run: written where asked, and no oracle labels."""
    run = make_run(backend="replay", name="r")
    out = tmp_path / "cli-report"
    result = CliRunner().invoke(app, ["report", str(run), "--out", str(out)])
    assert result.exit_code == 0, result.output
    index = out / "index.html"
    assert str(index) in result.output
    page = index.read_text()
    assert "ORACLE" not in page
    assert "replay:replay" in page
    svg = (index.parent / "figures" / "pearson_by_group_level.svg").read_text()
    assert "ORACLE" not in svg
    bad = CliRunner().invoke(app, ["report", str(tmp_path / "missing")])
    assert bad.exit_code != 0


def _check_viewer(index: Path, page: str) -> None:
    thumbs = re.findall(r'<img src="(frames/[^"]+)"', page)
    assert len(thumbs) == 30  # 3 episodes x 10 frames
    for src in thumbs:
        with Image.open(index.parent / src) as im:
            assert im.format == "JPEG" and max(im.size) <= 112
    assert page.count("<polyline") == 3 * 4  # per episode: ground truth + 3 methods
    assert 'class="tree"' in page and "frames 0–4" in page
    # the temporal-concat perception error is judged false and shown so
    assert 'class="v-false"' in page and 'class="v-true"' in page
    assert 'class="v-inconclusive"' in page


def _check_summary(run: Path, page: str) -> None:
    dataset = Path(json.loads((run / "run.json").read_text())["dataset"])
    rs = []
    for ep_dir in sorted((run / "traces").iterdir()):
        trace = Trace.load(next(ep_dir.glob("rover__*.json")))
        rs.append(score_progress(trace, read_episode(dataset, ep_dir.name, load_frames=False)))
    mean = sum(s.pearson for s in rs) / len(rs)
    row = re.search(r"ROVER</td>(.*?)</tr>", page, re.S)
    assert row and f"{mean:.2f} ±" in row.group(1)


def test_missing_run_dir_is_an_input_error(tmp_path: Path) -> None:
    with pytest.raises(InputError):
        build_report(tmp_path / "nope")
    (tmp_path / "empty").mkdir()
    with pytest.raises(InputError, match="no traces"):
        build_report(tmp_path / "empty")


def test_sweep_figures_from_a_real_eval_run(make_run, tmp_path: Path) -> None:
    """Frame-count and window sweeps (App. H, M) and App. G strata, via the real runner."""
    import asyncio

    from rover.eval.runner import EvalOptions, run_eval
    from rover.vlm.config import BackendConfig

    dataset = make_run().parent.parent / "dataset"
    opts = EvalOptions(
        dataset=dataset,
        methods=["rover", "gvl"],
        backends=["oracle"],
        frames=[5, 10],
        windows=[3, 6],
        out=tmp_path / "sweep",
        backend_config=BackendConfig(no_cache=True, jitter=5.0),
    )
    asyncio.run(run_eval(opts))
    index = build_report(tmp_path / "sweep")
    figures = {p.name for p in (index.parent / "figures").iterdir()}
    assert {"pearson_by_frame_count.svg", "window_ablation.svg"} <= figures
    # frame-level strata (App. G) come from the run's metrics.json
    assert {"pearson_by_context_state.svg", "error_rate_by_context_state.svg"} <= figures
    page = index.read_text()
    # the summary lists every configuration; the main figures say which setting they show
    for label in ("ROVER · 5 frames", "ROVER (window 6) · 10 frames", "GVL · 5 frames"):
        assert label in page
    assert "Shown at 10 frames per video" in page
