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
    _check_escaping(index, page)
    _check_oracle_labels(index, page)
    _check_viewer(run, index, page)
    _check_summary(run, page)
    _check_exports(run, index)


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


def _episode_pages(index: Path) -> dict[str, str]:
    return {p.stem: p.read_text() for p in sorted((index.parent / "episodes").glob("*.html"))}


def _check_escaping(index: Path, page: str) -> None:
    # the main page carries one script of ours (table sorting); model text is never markup
    assert page.lower().count("<script") == 1
    pages = _episode_pages(index)
    assert set(pages) == {"ep0", "ep1", "ep2"}
    for text in pages.values():
        assert "<script" not in text.lower()
    assert str(escape("<script>document.title='pwned'</script>")) in pages["ep0"]
    # subtasks in the reasoning tree are model text too
    assert "grasp the &lt;b&gt;can&lt;/b&gt;" in pages["ep0"]
    assert "plan: grasp the &lt;b&gt;can&lt;/b&gt; → place the can in the bin" in pages["ep0"]


def _check_oracle_labels(index: Path, page: str) -> None:
    assert page.count('id="oracle-banner"') == 1
    assert "ORACLE OUTPUT — answers come from simulator ground truth, not a VLM" in page
    assert "oracle:oracle" in page  # the backend is named
    # one banner, then one badge per section, not one per method and episode
    assert page.count('class="badge oracle"') == 4  # summary, figures, tables, episodes
    for text in _episode_pages(index).values():
        assert text.count('id="oracle-banner"') == 1 and 'class="badge oracle"' not in text


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


def _check_viewer(run: Path, index: Path, page: str) -> None:
    pages = _episode_pages(index)
    for text in pages.values():
        thumbs = re.findall(r'<img src="\.\./(frames/[^"]+)"', text)
        assert len(thumbs) == 10  # every frame the traces predicted, from the run's own frames
        for src in thumbs:
            with Image.open(index.parent / src) as im:
                assert im.format == "JPEG" and max(im.size) <= 112
        assert text.count("<polyline") == 4  # ground truth + 3 methods
        assert "frame index (original video)" in text and "task progress (%)" in text
        # every curve has a legend checkbox that hides it (CSS only)
        for i in range(3):
            assert f'id="show-{i}"' in text and f'class="curve-{i}"' in text
        assert not re.search(r"\b1 calls\b", text)
    text = pages["ep0"]
    assert 'class="tree"' in text and "frames 0–4" in text
    # the temporal-concat perception error is judged false and shown so
    assert 'class="v-false"' in text and 'class="v-true"' in text
    assert 'class="v-inconclusive"' in text
    # the main page shows the most informative episode (methods disagree most) first
    m = json.loads((run / "metrics.json").read_text())
    by_ep: dict[str, list[float]] = {}
    for r in m["per_trace"]:
        by_ep.setdefault(r["episode_id"], []).append(r["pearson"])
    top = max(by_ep, key=lambda e: max(by_ep[e]) - min(by_ep[e]))
    assert (
        f'<iframe class="episode" name="episode" title="episode viewer" src="episodes/{top}.html"'
        in page
    )
    assert page.count('target="episode"') == 3


def _check_summary(run: Path, page: str) -> None:
    """The page's main table is summary.md's, cell for cell."""
    summary = (run / "summary.md").read_text()
    md_row = next(line for line in summary.splitlines() if line.startswith("| ROVER |"))
    cells = [c.strip() for c in md_row.strip("|").split("|")]
    html_row = re.search(r"ROVER</td>(.*?)</tr>", page, re.S).group(1)
    assert re.findall(r'<td class="num">([^<]*)</td>', html_row) == cells[1:]
    dataset = Path(json.loads((run / "run.json").read_text())["dataset"])
    rs = []
    for ep_dir in sorted((run / "traces").iterdir()):
        trace = Trace.load(next(ep_dir.glob("rover__*.json")))
        rs.append(score_progress(trace, read_episode(dataset, ep_dir.name, load_frames=False)))
    mean = sum(s.pearson for s in rs) / len(rs)
    assert f"{mean:.2f} ±" in cells[1]


def _check_exports(run: Path, index: Path) -> None:
    import csv

    with open(index.parent / "predictions.csv", newline="") as fh:
        preds = list(csv.DictReader(fh))
    assert len(preds) == 3 * 3 * 10  # episodes x methods x frames
    injected = [p for p in preds if p["description"].startswith("<script>")]
    assert len(injected) == 1 and injected[0]["episode_id"] == "ep0"
    with open(index.parent / "episodes.csv", newline="") as fh:
        eps = list(csv.DictReader(fh))
    m = json.loads((run / "metrics.json").read_text())
    assert len(eps) == len(m["per_trace"]) == 9
    assert {float(e["pearson"]) for e in eps} == {r["pearson"] for r in m["per_trace"]}


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


def test_a_non_utf8_run_json_is_one_line_naming_the_file(tmp_path) -> None:
    from rover.run.store import RunStore

    (tmp_path / "run.json").write_bytes(b"\xff\xfe not json")
    with pytest.raises(InputError, match=r"run\.json: not a rover run configuration"):
        RunStore(tmp_path).config()
