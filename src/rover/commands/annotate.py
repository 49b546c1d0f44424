"""`rover annotate`: per-frame progress, subtask path and description for a whole dataset.

    rover annotate lerobot:/data/koch_pick --method rover --backend openai:gpt-4o \\
        --out annotations/koch --dry-run          # calls and tokens first, nothing spent
    rover annotate lerobot:/data/koch_pick --method rover --backend openai:gpt-4o \\
        --out annotations/koch --in-place         # + rover_progress.parquet beside meta/

Writes `frames.parquet` (one row per frame, keyed by episode_index and frame_index) and
`episodes.parquet` (VOC, final progress, success flag, tokens, calls per episode) into
`--out`; an interrupted run continues with `--resume` without repeating a call.
"""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from rover.console import make_console
from rover.errors import InputError
from rover.methods.registry import method_names
from rover.vlm import cli_options as vo


def register(app: typer.Typer) -> None:
    app.command("annotate")(annotate_command)


def annotate_command(
    source: Annotated[str, typer.Argument(help="Dataset or source spec (lerobot:, rlds:, ...).")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Folder for traces and tables.")],
    method: Annotated[
        str, typer.Option("--method", "-m", help=f"One of: {', '.join(method_names())}.")
    ] = "rover",
    backend: Annotated[
        str | None,
        typer.Option("--backend", "--vlm", help=vo.VLM_HELP + " (default: $ROVER_BACKEND)"),
    ] = None,
    in_place: Annotated[
        bool,
        typer.Option("--in-place", help="LeRobot: also write rover_progress.parquet beside meta/."),
    ] = False,
    episodes: Annotated[
        str | None,
        typer.Option("--episodes", help="Only these episodes: comma-separated ids or indices."),
    ] = None,
    sample: Annotated[
        int | None, typer.Option("--sample", help="Only N episodes drawn at random (--seed).")
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed for --sample and GVL.")] = 0,
    frames: Annotated[
        int | None, typer.Option("--frames", help="Sample N frames per episode (default: all).")
    ] = None,
    size: Annotated[int, typer.Option("--size", help="Long side of frames in px.")] = 256,
    view: Annotated[str | None, typer.Option("--view", help="Camera view to use.")] = None,
    task: Annotated[
        str | None, typer.Option("--task", help="Task text for sources that carry none.")
    ] = None,
    window: Annotated[
        int | None, typer.Option("--window", help="ROVER window size K (default 3).")
    ] = None,
    model_path: Annotated[
        Path | None, typer.Option("--model-path", help="clip-value: local CLIP/SigLIP folder.")
    ] = None,
    success_threshold: Annotated[
        float,
        typer.Option("--success-threshold", help="Final progress (%) that counts as success."),
    ] = 95.0,
    concurrency: Annotated[
        int, typer.Option("--concurrency", help="Episodes in flight at once.")
    ] = 4,
    calls_in_flight: Annotated[
        int | None, typer.Option("--calls-in-flight", help="VLM calls in flight (default 8).")
    ] = None,
    resume: Annotated[bool, typer.Option("--resume", help="Continue an interrupted run.")] = False,
    dry_run: Annotated[
        bool, typer.Option("--dry-run", help="Print calls and estimated tokens; call nothing.")
    ] = False,
    cache: vo.CacheOpt = None,
    no_cache: vo.NoCacheOpt = False,
    record: vo.RecordOpt = None,
    timeout: vo.TimeoutOpt = None,
    max_retries: vo.MaxRetriesOpt = None,
    api_key_env: vo.ApiKeyEnvOpt = None,
    detail: vo.DetailOpt = None,
    token_rule: vo.TokenRuleOpt = None,
    max_side: vo.ImageMaxSideOpt = None,
    temperature: vo.TemperatureOpt = None,
    max_tokens: vo.MaxTokensOpt = None,
    device: vo.DeviceOpt = None,
) -> None:
    """Annotate every episode of a dataset with a method's per-frame output (parquet)."""
    from rover.annotate.runner import AnnotateOptions, plan_annotation, run_annotate
    from rover.methods.registry import NON_VLM_METHODS

    config = vo.config_from_options(
        cache=cache,
        no_cache=no_cache,
        record=record,
        timeout=timeout,
        max_retries=max_retries,
        api_key_env=api_key_env,
        detail=detail,
        token_rule=token_rule,
        max_side=max_side,
        temperature=temperature,
        max_tokens=max_tokens,
        device=device,
        concurrency=calls_in_flight,
    )
    spec = backend if method in NON_VLM_METHODS else vo.resolve_backend(backend)
    if size <= 0:
        raise InputError(f"--size must be positive, got {size}")
    opts = AnnotateOptions(
        source=source,
        out=out,
        method=method,
        backend=spec or "none",
        backend_config=config,
        frames=frames,
        size=size,
        window=window,
        view=view,
        task=task,
        episodes=[e.strip() for e in episodes.split(",") if e.strip()] if episodes else None,
        sample=sample,
        seed=seed,
        success_threshold=success_threshold,
        concurrency=concurrency,
        resume=resume,
        in_place=in_place,
        model_path=model_path,
    )
    planned = plan_annotation(opts)
    console = make_console()  # no emoji codes or highlighting guessed in data
    if dry_run:
        _dry_run(opts, planned, console)
        return
    err = make_console(stderr=True)
    bar = Progress(
        TextColumn("[bold]annotate[/]"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("episodes"),
        TextColumn("{task.fields[info]}"),
        TimeElapsedColumn(),
        console=err,
    )
    job = bar.add_task(
        "annotate", total=len(planned.episodes), completed=len(planned.done), info=""
    )
    counts = {"calls": 0, "tokens": 0}

    def on_episode(episode_id: str, trace) -> None:
        if trace is not None:
            counts["calls"] += trace.totals.calls
            counts["tokens"] += trace.totals.total_tokens
        bar.update(job, advance=1, info=f"calls {counts['calls']:,}  tokens {counts['tokens']:,}")

    with bar:
        result = asyncio.run(run_annotate(opts, planned, on_episode))
    console.print(
        f"annotated {result.annotated} episode(s) with {method} "
        f"({result.skipped} already done, {len(result.failed)} failed): "
        f"{result.calls:,} calls, {result.tokens:,} tokens",
        soft_wrap=True,
    )
    if spec == "oracle":
        console.print(
            "[bold yellow]ORACLE[/] output: answers from simulator ground truth, not a VLM",
            soft_wrap=True,
        )
    console.print(f"frames:   {escape(str(result.frames_path))}", soft_wrap=True)
    console.print(f"episodes: {escape(str(result.episodes_path))}", soft_wrap=True)
    if result.in_place_path is not None:
        console.print(f"in place: {escape(str(result.in_place_path))}", soft_wrap=True)
    if result.failed:
        first = next(iter(result.failed.items()))
        err.print(
            f"[yellow]{len(result.failed)} episode(s) failed[/] (first: {escape(first[0])}: "
            f"{escape(first[1])}); see {out / 'errors.json'} and rerun with --resume",
            soft_wrap=True,
        )
        raise typer.Exit(1)


def _dry_run(opts, planned, console: Console) -> None:
    from rover.annotate.dryrun import DryRunVLM, estimate_annotation

    tally = asyncio.run(estimate_annotation(opts, planned))
    rule = DryRunVLM(opts.backend, opts.backend_config).rule if tally.calls else "-"
    console.print(
        f"dry run: {len(planned.pending)} episode(s) to annotate "
        f"({len(planned.done)} already done) with {opts.method} on {escape(opts.backend)}",
        soft_wrap=True,
    )
    console.print(
        f"  calls: {tally.calls:,}   estimated tokens: {tally.total_tokens:,} "
        f"({tally.prompt_tokens:,} prompt incl. {tally.image_tokens:,} image, "
        f"{tally.completion_tokens:,} completion; image rule {rule})",
        soft_wrap=True,
    )
    console.print(
        "  nothing was sent; ROVER makes a few more calls when the model splits the task "
        "into subtasks, and real replies are longer than the estimate's",
        soft_wrap=True,
    )
