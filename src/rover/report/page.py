"""The static HTML page: summary tables, the figures and the per-episode viewer.

Rendered with Jinja2 with autoescaping on, so model text (descriptions, subtasks, judge
reasons) always reaches the page as text, never as markup. The only unescaped inserts
are the progress charts, which `rover.report.viewer` builds from numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from jinja2 import Environment, FileSystemLoader, select_autoescape
from markupsafe import Markup

from rover import __version__
from rover.report.figures import FigureFile
from rover.report.run import RunData
from rover.report.scores import EpisodeScore, mean_se, variants_in_order
from rover.report.viewer import EpisodeView

TEMPLATES = Path(__file__).parent / "templates"

# summary columns: (attribute, header, digits)
SUMMARY_COLUMNS = [
    ("pearson", "Pearson r ↑", 2),
    ("l2", "L2 ↓", 1),
    ("voc", "VOC ↑", 2),
    ("frame_corr", "r with frame #", 2),
    ("error_rate", "Error rate % ↓", 1),
    ("success_rate", "Success rate % ↑", 1),
    ("qa_accuracy", "QA acc. % ↑", 1),
    ("qa_precision", "QA prec. %", 1),
    ("qa_recall", "QA recall %", 1),
]


@dataclass
class SummaryRow:
    variant: str
    color: str
    episodes: int
    cells: list[str]


@dataclass
class CostRow:
    variant: str
    num_frames: int
    episodes: int
    tokens: str
    calls: str


def render_page(
    run: RunData,
    rows: list[EpisodeScore],
    figures: list[FigureFile],
    episodes: list[EpisodeView],
    colors: dict[str, str],
    out: Path,
) -> Path:
    """Write `out/index.html` and return its path."""
    env = Environment(
        loader=FileSystemLoader(TEMPLATES),
        autoescape=select_autoescape(enabled_extensions=("html", "j2"), default=True),
    )
    env.filters["fmt"] = _fmt
    env.filters["trusted_svg"] = Markup  # only for charts built from numbers in viewer.py
    columns = [c for c in SUMMARY_COLUMNS if any(getattr(r, c[0]) is not None for r in rows)]
    summary = []
    for v in variants_in_order(rows):
        mine = [r for r in rows if r.variant == v]
        cells = []
        for attr, _, digits in columns:
            m, se, n = mean_se([getattr(r, attr) for r in mine])
            cells.append(_pm(m, se, n, digits))
        summary.append(SummaryRow(v, colors.get(v, "#555"), len(mine), cells))
    cost = []
    for v in variants_in_order(rows, "series"):
        for n in sorted({r.num_frames for r in rows if r.series == v}):
            mine = [r for r in rows if r.series == v and r.num_frames == n]
            cost.append(
                CostRow(
                    v,
                    n,
                    len(mine),
                    f"{mean_se([r.tokens for r in mine])[0]:,.0f}",
                    f"{mean_se([r.calls for r in mine])[0]:.1f}",
                )
            )
    html_text = env.get_template("index.html.j2").render(
        title=f"rover report: {run.run_dir.name}",
        run_dir=str(run.run_dir),
        dataset=str(run.dataset) if run.dataset else "not found",
        backends=run.backends,
        oracle=run.oracle,
        columns=[c[1] for c in columns],
        summary=summary,
        cost=cost,
        figures=figures,
        episodes=episodes,
        num_traces=len(run.traces),
        num_episodes=len({t.episode_id for t in run.traces}),
        shown_episodes=len(episodes),
        judged=any(r.error_rate is not None for r in rows),
        version=__version__,
        generated=datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
    )
    path = out / "index.html"
    tmp = path.with_name("index.html.tmp")
    tmp.write_text(html_text, encoding="utf-8")
    tmp.replace(path)
    return path


def _pm(mean: float, se: float, n: int, digits: int) -> str:
    if n == 0 or math.isnan(mean):
        return "—"
    if math.isnan(se):
        return f"{mean:.{digits}f}"
    return f"{mean:.{digits}f} ± {se:.{digits}f}"


def _fmt(value: float | None, digits: int = 1) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    return f"{value:.{digits}f}"
