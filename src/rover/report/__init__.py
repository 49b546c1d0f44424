"""Figures and the static HTML report for an evaluation run.

`build_report(run_dir)` reads the run directory (metrics.json's numbers, traces for the
viewer, the run's own frames), draws the paper's kinds of figures as PNG + SVG, and writes
`report/index.html` with one page per episode beside it, plus CSV exports. Oracle runs
carry one banner and a badge per section, so a demo can never be mistaken for a VLM's
results.
"""

from __future__ import annotations

import logging
from pathlib import Path

log = logging.getLogger(__name__)


def build_report(
    run_dir: Path, out: Path | None = None, *, dataset: Path | None = None, max_episodes: int = 0
) -> Path:
    """Write the report of `run_dir` into `out` (default RUN_DIR/report); return index.html.

    Args:
        run_dir: a run directory written by `rover eval` (self-contained: its episodes'
            ground truth and small frames are inside it).
        out: where to write the pages, figures, frames and CSV exports.
        dataset: for runs made before rover kept frames in the run: where to read them.
        max_episodes: episode pages to write, the most informative first (0: all).
    """
    from rover.report.export import write_exports
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
    episodes = build_episode_views(run, out, colors, rows)
    if max_episodes:
        episodes = episodes[:max_episodes]
    exports = write_exports(run, out)
    path = render_page(run, rows, figures, episodes, colors, out, exports)
    log.info("report written to %s", path)
    return path


__all__ = ["build_report"]
