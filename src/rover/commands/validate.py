"""`rover validate DATASET`: audit a generated dataset's ground truth against its facts."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from rover.console import esc
from rover.errors import InputError

SHOW_PROBLEMS = 20  # problems listed after the table (all of them with --all)
LEGEND = (
    "milestone: episodes showing their level's milestone and not the next; events: "
    "episodes whose events agree with the facts; teleports: episodes where an untouched "
    "object rises > 2 cm between frames; final progress: mean per level (must not fall); "
    "stalls: episodes with > 3 still expert frames in a row; joint: episodes whose "
    "progress gains < 0.25 (x 2/n in a task of n > 2 subtasks) while an articulated part "
    "moves to its goal; tries: mean/max "
    "per episode"
)


def audit_table(audits) -> Table:
    """The per-task audit table (also printed by `rover generate` after writing)."""
    table = Table(title="ground-truth audit", title_justify="left")
    for col, just in (
        ("task", "left"),
        ("eps", "right"),
        ("milestone", "right"),
        ("events", "right"),
        ("teleports", "right"),
        ("final progress L1..Ln", "left"),
        ("stalls", "right"),
        ("joint", "right"),
        ("tries", "right"),
        ("ok", "left"),
    ):
        table.add_column(col, justify=just, no_wrap=True)  # type: ignore[arg-type]
    for a in audits:
        means = " ".join(f"{m:.2f}" for m in a.level_means().values())
        order = "" if a.ordered() else " (falls)"
        tries = [t for v in a.tries.values() for t in v]
        table.add_row(
            esc(a.task),
            str(a.episodes),
            f"{a.milestones_met}/{a.episodes}",
            f"{a.events_ok}/{a.episodes}",
            str(a.untouched_moved),
            means + order,
            str(a.stalls),
            str(a.joint_lags),
            f"{sum(tries) / len(tries):.1f}/{max(tries)}" if tries else "-",
            "FAIL" if a.failed else "ok",
        )
    return table


def run_audit(root: Path, console, show_all: bool = False) -> int:
    """Audit the dataset at `root`, print the table and problems; returns the failure count."""
    from rover.io.dataset import load_dataset
    from rover.sim.audit import audit

    episodes = load_dataset(root, load_frames=False)
    if not episodes:
        raise InputError(f"{root}: the dataset has no episodes")
    audits = audit(episodes)
    console.print(audit_table(audits))
    console.print(LEGEND)
    problems = [p for a in audits for p in a.problems]
    shown = problems if show_all else problems[:SHOW_PROBLEMS]
    for p in shown:
        console.print(f"  - {esc(p)}")
    if len(shown) < len(problems):
        console.print(f"  ... and {len(problems) - len(shown)} more (--all lists them)")
    failed = sum(a.failed for a in audits)
    console.print(
        f"{len(episodes)} episodes, {len(audits)} tasks: "
        + (f"{failed} task(s) FAIL, {len(problems)} problem(s)" if failed else "all checks pass")
    )
    return failed


def validate_command(
    dataset: Annotated[Path, typer.Argument(help="Dataset directory (or 'bundled').")],
    show_all: Annotated[bool, typer.Option("--all", help="List every problem found.")] = False,
) -> None:
    """Audit a dataset: level milestones, events vs facts, teleports, progress order, stalls."""
    from rover.console import make_console

    root = dataset
    if str(dataset) == "bundled" and not dataset.exists():
        from rover.sim import bundled_dataset_path

        root = bundled_dataset_path()
    if not (root / "dataset.json").exists():
        raise InputError(f"{dataset}: not a rover dataset directory (no dataset.json)")
    wide = max(shutil.get_terminal_size((140, 24)).columns, 140)  # the table needs ~130
    if run_audit(root, make_console(width=wide), show_all) > 0:
        raise typer.Exit(1)


def register(app: typer.Typer) -> None:
    app.command("validate")(validate_command)
