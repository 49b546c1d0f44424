"""One fact, one place: every number of a run reads the same in metrics.json, the terminal
table, summary.md and the HTML report.

The run is built by the real runner on awkward inputs: two sources, two camera views,
then an unreadable QA answer, a trace of constant predictions and a unit whose trace is
missing; the run is rescored by the one scorer and every view is compared cell by cell.
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

from typer.testing import CliRunner

from rover.cli import app
from rover.commands.eval import _print_main_table
from rover.eval.results import compute_metrics, write_results
from rover.eval.rundir import RunDir
from rover.eval.summary import MAIN_COLUMNS, _fmt
from rover.methods.trace import Trace
from rover.report import build_report


def _awkward_run(tmp_path: Path, make_dataset) -> Path:
    a = make_dataset(tmp_path / "alpha", n=2, frames=8, wrist=True)
    b = make_dataset(tmp_path / "beta", n=2, frames=6, wrist=True)
    out = tmp_path / "run"
    res = CliRunner().invoke(
        app,
        [
            "eval",
            "--source",
            f"{a},{b}",
            "--views",
            "left,wrist",
            "--methods",
            "rover,gvl",
            "--backend",
            "oracle",
            "--jitter",
            "8",
            "--out",
            str(out),
        ],
        catch_exceptions=False,
    )
    assert res.exit_code == 0, res.output
    qa_file = next((out / "qa").rglob("rover__*v=left.json"))
    raw = json.loads(qa_file.read_text())
    raw["answers"][0].update(predicted=None, predicted_frame=None, raw="I cannot tell.")
    qa_file.write_text(json.dumps(raw))
    trace_file = next((out / "traces").rglob("gvl__*v=wrist.json"))
    trace = Trace.load(trace_file)
    for f in trace.frames:
        f.progress = 50.0  # a constant prediction: VOC and Pearson scored 0, and counted
    trace.save(trace_file)
    missing = sorted((out / "traces").rglob("rover__*v=wrist.json"))[-1]
    missing.unlink()  # a unit with no trace: "not run", left out of every mean
    rundir = RunDir(out)
    write_results(rundir, compute_metrics(rundir, json.loads((out / "run.json").read_text())))
    return out


def _md_main(summary: str) -> list[list[str]]:
    block = summary.split("## Main results")[1].split("\n\n")[1]
    rows = [r.strip().strip("|").split("|") for r in block.splitlines()[2:]]
    return [[c.strip() for c in r] for r in rows]


def _html_main(page: str) -> list[list[str]]:
    table = re.search(r'<table class="summary">(.*?)</table>', page, re.S).group(1)
    body = table.split("<tbody>")[1]
    return [
        [
            html.unescape(re.sub(r"<[^>]+>", "", c)).strip()
            for c in re.findall(r"<td[^>]*>(.*?)</td>", r, re.S)
        ]
        for r in re.findall(r"<tr>(.*?)</tr>", body, re.S)
    ]


def test_every_view_shows_the_same_numbers(tmp_path: Path, make_dataset, capsys) -> None:
    run = _awkward_run(tmp_path, make_dataset)
    metrics = json.loads((run / "metrics.json").read_text())
    rows = metrics["per_trace"]
    # the awkward cases are in the data
    assert any(r["error"] == "not run" for r in rows)
    assert metrics["counts"]["voc_constant"] == 1
    assert {r["dataset"] for r in rows} == {"alpha", "beta"}
    unreadable = [r for r in rows if r.get("qa_unreadable")]
    assert len(unreadable) == 1
    # the unreadable answer is wrong, not dropped: 3 of 4 right is 75%, never 100%
    assert unreadable[0]["qa_accuracy"] == 75.0

    # expected cells, straight from metrics.json's aggregates
    agg = {
        (a["variant"], a["metric"]): a
        for a in metrics["aggregates"]
        if a["by"] == "all" and a["group"] == "all"
    }
    expected = []
    for v in metrics["variants"]:
        cells = [v["label"], v["view"]]
        for _, _, metric, digits in MAIN_COLUMNS:
            a = agg.get((v["id"], metric))
            if a is not None and a["mean"] is not None:
                cells.append(_fmt(a["mean"], a["se"], digits))
        n = max(agg[(v["id"], m)]["n"] for m in ("pearson", "total_tokens"))
        expected.append(cells + [str(n)])
        # per-video means: the aggregate is the mean of the per-trace rows
        mine = [r["qa_accuracy"] for r in rows if r["variant"] == v["id"] and r["error"] is None]
        assert agg[(v["id"], "qa_accuracy")]["mean"] == sum(mine) / len(mine)

    md = _md_main((run / "summary.md").read_text())
    assert md == expected

    page = build_report(run).read_text()
    assert _html_main(page) == expected

    # summary.md's other tables are the page's tables too (pivots, App. L, cost, errors)
    summary = (run / "summary.md").read_text()
    for title in ("App. L: VOC by dataset", "Inference cost (App. F)", "by camera view"):
        assert title in summary and title in page
    for cell in re.findall(r"\| ([0-9.,]+ ± [0-9.,]+ \(n=\d+\)) \|", summary):
        assert cell in page

    # the terminal: the same means (SE only in summary.md), at 80 columns
    _print_main_table(metrics, oracle=True)
    term = capsys.readouterr().out
    assert max(len(x) for x in term.splitlines()) <= 80
    lines = [x.split() for x in term.splitlines() if x.strip().startswith(("ROVER", "GVL"))]
    assert len(lines) == len(expected)
    for got, want in zip(lines, expected, strict=True):
        means = [c.split(" ± ")[0] for c in want[2:-1]]
        assert got[:2] == want[:2]
        assert set(got[2:]) <= set(means)  # compact: a subset of the columns, same digits
        assert len(got) >= 2 + 6
