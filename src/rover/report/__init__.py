"""Figures and the static HTML report for an evaluation run.

`build_report(run_dir)` reads the run's traces (and the dataset they came from), scores
them, draws the paper's kinds of figures as PNG + SVG, and writes one self-contained page,
`report/index.html`, with a per-episode viewer. Oracle runs are labelled as such on every
figure and section, so a demo can never be mistaken for a VLM's results.
"""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger(__name__)


def build_report(
    run_dir: Path, out: Path | None = None, *, dataset: Path | None = None, max_episodes: int = 40
) -> Path:
    """Write the report of `run_dir` into `out` (default RUN_DIR/report); return index.html.

    Args:
        run_dir: a run directory written by `rover eval` (any folder of trace JSON files
            works; the dataset is found through the run's config or `dataset`).
        out: where to write the page, figures and thumbnails.
        dataset: the dataset directory the traces came from, when the run does not say.
        max_episodes: how many episodes the viewer shows (the page stays light).
    """
    from rover.report.figures import variant_colors, write_figures
    from rover.report.page import render_page
    from rover.report.run import load_run
    from rover.report.scores import score_run
    from rover.report.viewer import build_episode_views

    run = load_run(Path(run_dir), dataset=dataset)
    out = Path(out) if out is not None else Path(run_dir) / "report"
    out.mkdir(parents=True, exist_ok=True)
    rows = score_run(run)
    colors = variant_colors(rows)
    figures = write_figures(rows, out / "figures", oracle=run.oracle, aggregates=run.aggregates)
    episodes = build_episode_views(run, out, colors, max_episodes=max_episodes)
    path = render_page(run, rows, figures, episodes, colors, out)
    log.info("report written to %s", path)
    return path


__all__ = ["build_report"]
