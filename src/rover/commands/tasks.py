"""`rover tasks`: every benchmark task, what it consists of and how well its expert does.

A user should see what exists without reading code: per task its suite, group (the
paper's Table 4 name for the kitchen suite), object-centric subtasks, levels (number and
names), frames per video and the scripted expert's success. Expert success is only ever
a measured number, read from the record `benchmarks/expert_success.py --write` keeps
(`rover.sim.expert_record`), with its seeds and date; "not measured" where there is
none, and marked stale when the task changed after it was measured.
"""

from __future__ import annotations

import json
from typing import Annotated, Any

import typer
from rich import box
from rich.table import Table

from rover.console import esc, make_console
from rover.errors import InputError


def task_rows(suite: str = "all", names: list[str] | None = None) -> list[dict[str, Any]]:
    """One JSON-able description per task (the `--json` output)."""
    from rover.sim.expert_record import RECORD, expert_success, read_records
    from rover.sim.kitchen.presets import group_title, paper_group_of
    from rover.sim.tasks import get_task, task_names

    records = read_records()
    rows = []
    for name in names or task_names(suite):
        spec = get_task(name)
        expert = expert_success(spec, records)
        if expert["measured"]:
            expert["source"] = f"{RECORD.name}, benchmarks/expert_success.py --write"
        rows.append(
            {
                "name": spec.name,
                "suite": spec.suite,
                "group": spec.group,
                "group_title": group_title(spec.group),
                "paper_task": spec.suite == "kitchen" and paper_group_of(spec.name) is not None,
                "description": spec.description,
                "subtasks": [s.name for s in spec.subtasks],
                "levels": [{"level": lv.level, "name": lv.name} for lv in spec.levels],
                "milestones": list(spec.milestones),
                "questions": [q.text for q in spec.qa_templates],
                "frames": spec.frames,
                "expert": spec.expert,
                "expert_success": expert,
            }
        )
    return rows


def _table(rows: list[dict[str, Any]]) -> Table:
    """A task's name with its subtasks under it, so a narrow terminal still reads well."""
    suites = len({r["suite"] for r in rows}) > 1
    table = Table(title="rover tasks", title_justify="left", box=box.SIMPLE_HEAD, pad_edge=False)
    table.add_column("task: subtasks", ratio=1, min_width=30)
    if suites:
        table.add_column("suite", no_wrap=True)
    table.add_column("group", max_width=18)
    table.add_column("levels", justify="right", no_wrap=True)
    table.add_column("frames", justify="right", no_wrap=True)
    table.add_column("expert", no_wrap=True)
    for r in rows:
        e = r["expert_success"]
        cell = "not measured"
        if e["measured"]:
            cell = f"{e['successes']}/{e['seeds']}" + (" stale" if e["stale"] else "")
        table.add_row(
            f"[bold]{esc(r['name'])}[/bold]\n  [dim]{esc(' → '.join(r['subtasks']))}[/dim]",
            *([esc(r["suite"])] if suites else []),
            esc(r["group_title"]),
            str(len(r["levels"])),
            str(r["frames"]),
            esc(cell),
        )
    return table


def _detail(console, r: dict[str, Any]) -> None:
    console.print(f"[bold]{esc(r['name'])}[/bold]  ({esc(r['suite'])}, {esc(r['group_title'])})")
    console.print(f"  instruction: {esc(r['description'])}")
    console.print(f"  subtasks: {esc(' → '.join(r['subtasks']))}")
    console.print(f"  levels ({len(r['levels'])}), frames {r['frames']}:")
    for lv in r["levels"]:
        console.print(f"    {lv['level']}: {esc(lv['name'])}")
    console.print(f"  milestones: {esc(', '.join(r['milestones']) or '-')}")
    for q in r["questions"]:
        console.print(f"  QA: {esc(q)}")
    e = r["expert_success"]
    if e["measured"]:
        stale = " [stale: the task or its fixture changed since]" if e["stale"] else ""
        console.print(
            f"  expert {esc(r['expert'])}: {e['successes']}/{e['seeds']} on seeds "
            f"{e['first_seed']}..{e['first_seed'] + e['seeds'] - 1}, measured {e['date']}"
            f"{esc(stale)} ({esc(e['source'])})"
        )
    else:
        console.print(f"  expert {esc(r['expert'])}: success not measured")


def _paper_note(rows: list[dict[str, Any]]) -> str:
    """How much of the paper's Table 4 the kitchen suite covers."""
    from rover.sim.kitchen.presets import PAPER_GROUPS, paper_task_names

    have = {r["name"] for r in rows if r["paper_task"]}
    names = paper_task_names()
    groups = {
        gid for gid, g in PAPER_GROUPS.items() if any(f"kitchen.{t}" in have for t in g.tasks)
    }
    missing = [n for n in names if n not in have]
    note = (
        f"kitchen: {len(have)} of the paper's {len(names)} tasks, in {len(groups)} of its "
        f"{len(PAPER_GROUPS)} groups (App. B, Table 4)"
    )
    return note + (f"; not built yet: {', '.join(missing)}" if missing else "")


def tasks_command(
    names: Annotated[
        list[str] | None, typer.Argument(help="Tasks to show in full (default: list all).")
    ] = None,
    suite: Annotated[str, typer.Option(help="Suite: tabletop, kitchen or all.")] = "all",
    as_json: Annotated[bool, typer.Option("--json", help="Print JSON (everything).")] = False,
) -> None:
    """List the benchmark tasks: suite, group, subtasks, levels, frames, expert success."""
    from rover.sim.tasks import get_task, task_names

    task_names(suite)  # an unknown suite: one line naming the valid ones
    if names:
        for n in names:
            get_task(n)
        wrong = [n for n in names if suite != "all" and get_task(n).suite != suite]
        if wrong:
            raise InputError(f"not in suite {suite!r}: {', '.join(wrong)}")
    rows = task_rows(suite, names)
    if as_json:
        typer.echo(json.dumps(rows, indent=1, ensure_ascii=False))
        return
    console = make_console()
    if names:
        for r in rows:
            _detail(console, r)
        return
    console.print(_table(rows))
    if suite in ("all", "kitchen"):
        console.print(esc(_paper_note(rows)))
    dates = sorted({r["expert_success"]["date"] for r in rows if r["expert_success"]["measured"]})
    when = (
        f", measured {dates[0]}" + (f" to {dates[-1]}" if len(dates) > 1 else "") if dates else ""
    )
    console.print(
        "expert: scripted-expert successes / seeds, from `python benchmarks/expert_success.py "
        f"--write` (src/rover/sim/expert_success.json{when}); `rover tasks NAME` shows a "
        "task's levels, milestones, questions and its measurement, --json everything"
    )


def register(app: typer.Typer) -> None:
    app.command("tasks")(tasks_command)
