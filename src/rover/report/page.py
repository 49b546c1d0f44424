"""The static HTML pages: the main page (tables, figures, episode index) and one per episode.

Rendered with Jinja2 with autoescaping on, so model text (descriptions, subtasks, judge
reasons) always reaches the page as text, never as markup. The only unescaped inserts
are the progress charts, which `rover.report.viewer` builds from numbers. The tables are
`rover.eval.summary.run_tables(metrics)`, the very cells summary.md prints, so the page
and summary.md cannot disagree.
"""

from __future__ import annotations

import math
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from jinja2 import Environment, FileSystemLoader, select_autoescape
from markupsafe import Markup

from rover import __version__
from rover.eval.summary import run_tables
from rover.report.figures import FigureFile
from rover.report.run import RunData
from rover.report.scores import EpisodeScore, variants_in_order
from rover.report.viewer import EpisodeView

TEMPLATES = Path(__file__).parent / "templates"


def _env() -> Environment:
    env = Environment(
        loader=FileSystemLoader(TEMPLATES),
        autoescape=select_autoescape(enabled_extensions=("html", "j2"), default=True),
    )
    env.filters["fmt"] = _fmt
    env.filters["count"] = count
    env.filters["trusted_svg"] = Markup  # only for charts built from numbers in viewer.py
    return env


def render_page(
    run: RunData,
    rows: list[EpisodeScore],
    figures: list[FigureFile],
    episodes: list[EpisodeView],
    colors: dict[str, str],
    out: Path,
    exports: dict[str, Any],
) -> Path:
    """Write `out/index.html` and `out/episodes/*.html`; return the main page's path."""
    env = _env()
    page = env.get_template("episode.html.j2")
    (out / "episodes").mkdir(parents=True, exist_ok=True)
    for ep in episodes:
        _write(out / "episodes" / f"{ep.slug}.html", page.render(ep=ep, oracle=run.oracle))
    series = variants_in_order(rows)
    ep_scores: dict[str, dict[str, float | None]] = {}
    for r in rows:
        ep_scores.setdefault(r.episode_id, {})[r.variant] = r.pearson
    cfg = run.config
    text = env.get_template("index.html.j2").render(
        title=f"rover report: {run.run_dir.name}",
        run_dir=str(run.run_dir),
        data=cfg.get("dataset") or ", ".join(cfg.get("sources", [])) or "unknown",
        judge=_judge(run, "judge"),
        answerer=_judge(run, "answerer"),
        backends=run.backends,
        oracle=run.oracle,
        tables=run_tables(run.metrics),
        notes=run.metrics.get("notes", []),
        colors=colors,
        figures=figures,
        episodes=episodes,
        series=series,
        ep_scores=ep_scores,
        multi_dataset=len({e.dataset for e in episodes}) > 1,
        exports=exports,
        num_traces=len(run.entries),
        num_episodes=len(episodes),
        version=__version__,
        generated=datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
    )
    path = out / "index.html"
    _write(path, text)
    return path


def _judge(run: RunData, role: str) -> str:
    facts = run.metrics.get("judges", {})
    name = facts.get(f"{role}_name") or facts.get(role) or run.config.get(role) or "—"
    agree = facts.get(f"{role}_agreement")
    return f"{name} (measured agreement: {agree})" if agree is not None else str(name)


def _write(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)


def count(n: int, noun: str) -> str:
    """'1 call', '2 calls', '1,204 tokens'."""
    return f"{n:,} {noun}" + ("" if n == 1 else "s")


def _fmt(value: float | None, digits: int = 1) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    return f"{value:.{digits}f}"
