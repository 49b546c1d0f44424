"""`rover report RUN_DIR`: figures and a static HTML page for an evaluation run."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from rover.console import esc, make_console
from rover.errors import InputError
from rover.paths import check_output_dir


def register(app: typer.Typer) -> None:
    app.command("report")(report)


def report(
    run_dir: Annotated[Path, typer.Argument(help="Run directory written by `rover eval`.")],
    out: Annotated[
        Path | None,
        typer.Option("--out", "-o", help="Where to write the report (default: RUN_DIR/report)."),
    ] = None,
    dataset: Annotated[
        Path | None,
        typer.Option(
            "--dataset",
            help="Only for runs made before rover kept frames in the run: where they are.",
        ),
    ] = None,
    max_episodes: Annotated[
        int,
        typer.Option(
            "--max-episodes",
            min=0,
            help="Episode pages to write, most informative first (0: all).",
        ),
    ] = 0,
) -> None:
    """Draw the paper's figures (PNG + SVG), write the HTML report with one page per
    episode, and export per-frame predictions and per-episode scores as CSV."""
    from rover.report import build_report

    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: no such run directory (write one with rover eval --out)")
    if out is not None:  # before drawing anything: never into somebody else's folder
        check_output_dir(out, "--out", marker="index.html")
    console = make_console()
    with console.status("building report"):
        index = build_report(run_dir, out, dataset=dataset, max_episodes=max_episodes)
    console.print(f"report: {esc(index)}", soft_wrap=True)
    console.print(f"open it: {esc(index.resolve().as_uri())}", soft_wrap=True)
