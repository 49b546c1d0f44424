"""`rover generate`: build a benchmark dataset of perturbed robosuite videos with truth."""

from __future__ import annotations

import logging
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from rover.console import esc, make_console
from rover.errors import InputError
from rover.exec.options import RayAddressOpt
from rover.paths import check_output_dir

MAX_SIZE = 1024  # px: the offscreen framebuffer grows with the square of the size


def _split(value: str) -> list[str]:
    return [v.strip() for v in value.split(",") if v.strip()]


def generate_command(
    ctx: typer.Context,
    out: Annotated[Path, typer.Option("--out", "-o", help="Dataset directory (resumed).")],
    tasks: Annotated[str, typer.Option(help="Comma-separated task names.")] = "Lift",
    per_level: Annotated[int, typer.Option(help="Videos per level per task.")] = 3,
    levels: Annotated[str, typer.Option(help="Levels: 'all' or e.g. '1,3,last'.")] = "all",
    frames: Annotated[
        int, typer.Option(help="Frames per video (0: 30 atomic / 60 composite; max 240).")
    ] = 0,
    views: Annotated[str, typer.Option(help="Views: wrist, left, right.")] = "left,wrist",
    size: Annotated[int, typer.Option(help="Frame width and height in px.")] = 256,
    seed: Annotated[int, typer.Option(help="Seed: same seed, same dataset.")] = 0,
    workers: Annotated[int, typer.Option(help="Parallel worker processes.")] = 1,
    executor: Annotated[
        str, typer.Option("--executor", help="Where episodes run: 'local' (--workers) or 'ray'.")
    ] = "local",
    ray_address: RayAddressOpt = None,
    demos: Annotated[int, typer.Option(help="Expert demonstrations per task.")] = 3,
    source_hdf5: Annotated[
        Path | None,
        typer.Option("--source-hdf5", help="robomimic/RoboCasa HDF5 to use as expert demos."),
    ] = None,
    progress_form: Annotated[
        str,
        typer.Option(
            "--progress-form",
            help="Progress: 'rover' (documented departures from Sec. 4.2) or 'paper'.",
        ),
    ] = "rover",
    preset: Annotated[
        str | None,
        typer.Option(
            help="'paper': the paper's dataset (27 kitchen tasks, Table 5's videos per level, "
            "30/60 frames, views wrist,left,right, 256 px; --views/--size still apply).",
        ),
    ] = None,
    available_only: Annotated[
        bool,
        typer.Option(
            "--available-only", help="With --preset: write only the preset's tasks that exist."
        ),
    ] = False,
) -> None:
    """Generate perturbed robosuite videos with ground-truth progress, facts, events and QA."""
    from rover.exec import check_executor, make_executor
    from rover.sim.generate import MAX_FRAMES, GenerateConfig, generate
    from rover.sim.render import check_views
    from rover.sim.tasks import get_task

    check_executor(executor, ray_address)  # a missing extra: one line, before any work
    level_counts: dict[str, list[int]] = {}
    if preset is not None:
        tasks, level_counts, views, size = _preset(ctx, preset, available_only, views, size)
    elif available_only:
        raise InputError("--available-only goes with --preset")
    task_list = _split(tasks)
    if not task_list:
        raise InputError("--tasks is empty")
    for t in task_list:
        get_task(t)
    view_list = _split(views)
    check_views(view_list)
    if per_level < 1 or size < 16 or workers < 1 or demos < 1:
        raise InputError("--per-level, --workers and --demos must be >= 1, --size >= 16")
    if size > MAX_SIZE:
        raise InputError(f"--size must be at most {MAX_SIZE} px, got {size}")
    if not 0 <= frames <= MAX_FRAMES:
        raise InputError(
            f"--frames must be 0 (the task's default) or 1..{MAX_FRAMES}, got {frames}"
        )
    if not view_list:
        raise InputError("--views is empty; give e.g. left,wrist")
    _check_levels(task_list, _split(levels))
    if source_hdf5 is not None and not source_hdf5.exists():
        raise InputError(f"--source-hdf5 {source_hdf5}: no such file")
    if progress_form not in ("rover", "paper"):
        raise InputError(f"--progress-form must be 'rover' or 'paper', got {progress_form!r}")
    cfg = GenerateConfig(
        tasks=task_list,
        per_level=per_level,
        levels=_split(levels),
        frames=frames or None,
        views=view_list,
        size=size,
        seed=seed,
        demos=demos,
        source_hdf5=str(source_hdf5) if source_hdf5 else None,
        progress_form=progress_form,  # type: ignore[arg-type]
        level_counts=level_counts,
    )
    check_output_dir(out, "--out", marker="dataset.json")
    _check_resume(out, cfg)
    ex = make_executor(executor, workers=workers, address=ray_address)
    logging.getLogger("robosuite").setLevel(logging.ERROR)
    console = make_console(stderr=True)
    start = time.perf_counter()
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=console,
    ) as bar:
        ids: dict[str, int] = {}

        def on_progress(stage: str, done: int, total: int) -> None:
            if stage not in ids:
                ids[stage] = bar.add_task(
                    "expert demos" if stage == "demos" else "episodes", total=total
                )
            bar.update(ids[stage], completed=done, total=total)

        written = generate(cfg, out, workers=workers, on_progress=on_progress, executor=ex)
    took = time.perf_counter() - start
    console.print(f"wrote {len(written)} episodes to {esc(out)} in {took:.1f}s")
    from rover.commands.validate import run_audit

    wide = make_console(stderr=True, width=max(console.width, 140))
    if run_audit(out, wide) > 0:  # the same audit as `rover validate OUT`
        raise typer.Exit(1)


def _preset(
    ctx: typer.Context, preset: str, available_only: bool, views: str, size: int
) -> tuple[str, dict[str, list[int]], str, int]:
    """--preset paper: its tasks and per-level counts (`rover.sim.kitchen.presets`), and
    its views and size unless given; options that would change its shape are refused."""
    from rover.sim.kitchen.presets import PAPER_SIZE, PAPER_VIEWS, paper_plan
    from rover.sim.tasks import task_names

    if preset != "paper":
        raise InputError(f"--preset must be 'paper', got {preset!r}")

    def given(name: str) -> bool:
        source = ctx.get_parameter_source(name)
        return getattr(source, "name", "DEFAULT") not in ("DEFAULT", "DEFAULT_MAP")

    shape = ("tasks", "per_level", "levels", "frames")
    clash = [f"--{n.replace('_', '-')}" for n in shape if given(n)]
    if clash:
        raise InputError(f"--preset paper sets {', '.join(clash)} itself; leave them out")
    names, counts, note = paper_plan(task_names("all"), available_only)
    make_console(stderr=True).print(esc(note))
    return (
        ",".join(names),
        counts,
        views if given("views") else ",".join(PAPER_VIEWS),
        size if given("size") else PAPER_SIZE,
    )


# settings that change what an episode looks like: a dataset never mixes two values
_EPISODE_SETTINGS = ("frames", "views", "size", "seed", "demos", "source_hdf5", "progress_form")


def _check_levels(tasks: list[str], wanted: list[str]) -> None:
    """Every level number asked for exists in every task (`--levels 99` is not `last`)."""
    from rover.sim.tasks import get_task

    for w in wanted:
        if w in ("all", "last"):
            continue
        if not w.isdigit():
            raise InputError(f"--levels: {w!r} is not a level number, 'last' or 'all'")
        for t in tasks:
            have = sorted(lv.level for lv in get_task(t).levels)
            if int(w) not in have:
                raise InputError(
                    f"--levels {w}: task {t} has levels {', '.join(map(str, have))} "
                    "(or use 'last' / 'all')"
                )


def _check_resume(out: Path, cfg) -> None:
    """Refuse to add episodes to a dataset made with other settings (one line naming them)."""
    from rover.io.dataset import DATASET_FILE, read_dataset_info

    if not (out / DATASET_FILE).exists():
        return
    before = read_dataset_info(out).generator
    if not before:
        raise InputError(f"{out} holds a dataset rover generate did not make; use a new --out")
    now = cfg.model_dump(mode="json")
    differ = [k for k in _EPISODE_SETTINGS if k in before and before.get(k) != now.get(k)]
    if differ:
        said = ", ".join(f"--{k.replace('_', '-')} {before[k]!r} (now {now[k]!r})" for k in differ)
        raise InputError(
            f"{out} was generated with other settings: {said}; "
            "use a new --out or the same settings to resume"
        )


def register(app: typer.Typer) -> None:
    app.command("generate")(generate_command)
