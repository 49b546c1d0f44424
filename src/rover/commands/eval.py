"""`rover eval`: run methods over a dataset, score them, write paper-style tables."""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import (
    BarColumn,
    Progress,
    TextColumn,
    TimeElapsedColumn,
    TimeRemainingColumn,
)
from rich.table import Table

from rover.console import esc, line, make_console
from rover.errors import InputError
from rover.exec.options import RayAddressOpt
from rover.paths import check_output_dir
from rover.vlm import cli_options as vo

HELP = "Evaluate reasoning methods on a dataset: progress, frame reasoning, video QA, cost."


def register(app: typer.Typer) -> None:
    app.command("eval", help=HELP)(eval_command)


def eval_command(
    out: Annotated[Path, typer.Option("--out", help="Run directory to write (RUN_DIR).")],
    dataset: Annotated[
        Path | None,
        typer.Option(
            "--dataset",
            help="A rover dataset directory ('bundled': the small one shipped with rover).",
        ),
    ] = None,
    source: Annotated[
        str | None,
        typer.Option(
            "--source",
            help="Instead of --dataset: source spec(s), comma-separated "
            "(lerobot:PATH, rlds:PATH, hdf5:PATH, a video file, a dataset dir...)",
        ),
    ] = None,
    task: Annotated[
        str | None,
        typer.Option(
            "--task", help="With --source: the task text of every episode (single-task sources)."
        ),
    ] = None,
    methods: Annotated[
        str, typer.Option("--methods", help="Comma-separated method names.")
    ] = "rover,gvl,temporal-concat,local-concat",
    backend: Annotated[
        str | None,
        typer.Option(
            "--backend",
            "--vlm",
            help="VLM spec(s), comma-separated ("
            + vo.VLM_HELP.removeprefix("VLM spec: ")
            + "); default: ROVER_BACKEND or the config file",
        ),
    ] = None,
    judge: Annotated[
        str, typer.Option("--judge", help="Task 2 judge: 'rule', a VLM spec, or 'none'.")
    ] = "rule",
    answerer: Annotated[
        str, typer.Option("--answerer", help="Task 3 QA answerer: 'rule', a VLM spec, or 'none'.")
    ] = "rule",
    concurrency: Annotated[
        int, typer.Option("--concurrency", help="Episodes in flight at once.")
    ] = 16,
    calls_in_flight: Annotated[
        int | None,
        typer.Option(
            "--calls-in-flight", help="VLM calls in flight per backend (default: --concurrency)."
        ),
    ] = None,
    executor: Annotated[
        str, typer.Option("--executor", help="Where work units run: 'local' or 'ray'.")
    ] = "local",
    ray_address: RayAddressOpt = None,
    limit: Annotated[int | None, typer.Option("--limit", help="Only the first N episodes.")] = None,
    episodes: Annotated[
        int | None,
        typer.Option(
            "--episodes", help="Sample N episodes per dataset/source (reproducible with --seed)."
        ),
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed for --episodes sampling.")] = 0,
    frames: Annotated[
        str | None,
        typer.Option("--frames", help="Frames per video, comma-separated sweep (default: all)."),
    ] = None,
    window: Annotated[
        str | None,
        typer.Option("--window", help="ROVER window sizes, comma-separated sweep (default: 3)."),
    ] = None,
    views: Annotated[
        str | None,
        typer.Option(
            "--views", help="Camera views, comma-separated sweep (default: episode's own)."
        ),
    ] = None,
    resume: Annotated[bool, typer.Option("--resume", help="Continue an interrupted run.")] = False,
    report: Annotated[
        bool, typer.Option("--report", help="Build the HTML report at the end.")
    ] = False,
    flip_prob: Annotated[
        float | None,
        typer.Option(
            "--flip-prob", help="Oracle noise: probability of flipping each described fact."
        ),
    ] = None,
    jitter: Annotated[
        float | None,
        typer.Option(
            "--jitter", help="Oracle noise: std. dev. of progress noise (percentage points)."
        ),
    ] = None,
    model_path: Annotated[
        Path | None,
        typer.Option("--model-path", help="clip-value: local CLIP/SigLIP model folder."),
    ] = None,
    oracle_seed: Annotated[
        int | None, typer.Option("--oracle-seed", help="Oracle noise seed.")
    ] = None,
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
    """Evaluate reasoning methods on a dataset: progress, frame reasoning, video QA, cost."""
    from rover.eval.runner import EvalOptions, finish_run, prepare_run
    from rover.eval.variants import parse_int_list, parse_name_list, split_backend_specs
    from rover.exec import check_executor, key_env_names, make_executor
    from rover.io.source import spec_with_options

    check_executor(executor, ray_address)  # a missing extra: one line, before any work
    if executor == "ray" and record is not None:
        raise InputError("--record writes one cassette in this process: use --executor local")
    if concurrency < 1:
        raise InputError(f"--concurrency must be at least 1, got {concurrency}")
    if calls_in_flight is not None and calls_in_flight < 1:  # 0 is not "unset"
        raise InputError(f"--calls-in-flight must be at least 1, got {calls_in_flight}")
    check_output_dir(out, "--out", allow_nonempty=True)  # the run directory says if it is a run
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
        concurrency=concurrency if calls_in_flight is None else calls_in_flight,
        flip_prob=flip_prob,
        jitter=jitter,
        seed=oracle_seed,
    )
    if dataset is not None and source is not None:
        raise InputError("give either --dataset or --source, not both")
    if dataset is None and source is None:
        raise InputError("give the data to evaluate: --dataset DIR or --source SPEC")
    if task is not None and (dataset is not None or not task.strip()):
        raise InputError(
            "--task needs non-empty text and applies to --source only (datasets carry tasks)"
        )
    if dataset is not None and str(dataset) == "bundled" and not dataset.exists():
        from rover.sim import bundled_dataset_path

        dataset = bundled_dataset_path()
    opts = EvalOptions(
        dataset=dataset,
        sources=[spec_with_options(s, task=task) for s in parse_name_list(source, "--source")]
        if source
        else [],
        methods=parse_name_list(methods, "--methods"),
        backends=split_backend_specs(vo.resolve_backend(backend)),
        judge=judge.strip(),
        answerer=answerer.strip(),
        frames=parse_int_list(frames, "--frames", minimum=2),
        windows=parse_int_list(window, "--window", minimum=2),
        views=[v for v in parse_name_list(views, "--views")] if views else [None],
        concurrency=concurrency,
        limit=limit,
        episodes=episodes,
        seed=seed,
        out=out,
        resume=resume,
        model_path=model_path,
        backend_config=config,
        command=["rover"] + sys.argv[1:],
    )
    err = make_console(stderr=True)
    # one line that fits 80 columns; the bar and ETA follow work units, and calls / tokens
    # move with every VLM call (a ROVER episode against a real API is ~40 calls)
    progress = Progress(
        TextColumn("[bold]eval[/]"),
        BarColumn(bar_width=12),
        TextColumn("{task.fields[info]}"),
        TimeElapsedColumn(),
        TextColumn("eta"),
        TimeRemainingColumn(),
        console=err,
        transient=False,
    )
    task_id = progress.add_task("eval", total=None, info="")

    def on_update(state) -> None:
        info = (
            f"ep {state.episodes_done}/{state.episodes_total} calls {state.calls:,} "
            f"tok {_short(state.tokens)} err {state.errors}"
        )
        # units skipped on --resume are not work done now: leave them out of the ETA's rate
        progress.update(
            task_id,
            total=max(1, state.units_total - state.units_skipped),
            completed=state.units_done - state.units_skipped,
            info=info,
        )

    ex = make_executor(executor, address=ray_address, env_keys=key_env_names(config))
    for name in getattr(ex, "missing_env", []):
        err.print(
            f"[yellow]warning:[/] {name} is set here but not on the Ray cluster's workers, "
            "which read keys from their own environment (docs/distributed.md)"
        )
    runner = prepare_run(opts, on_update, executor=ex)
    with ex, progress:
        state, metrics = asyncio.run(finish_run(runner))
    _print_main_table(metrics, oracle="oracle" in opts.backends)
    out_console = make_console()
    out_console.print(f"run directory: {esc(out)}  (metrics.json, summary.md)")
    if state.errors:
        last = f" (last: {esc(line(state.last_error, 160))})" if state.last_error else ""
        err.print(
            f"[yellow]{state.errors} of {state.units_total} work unit(s) failed[/]{last}; "
            f"see {esc(out / 'errors.jsonl')} (rerun with --resume to retry them)",
            soft_wrap=True,
        )
    if report:
        _build_report(out, err)
    if state.errors or metrics["counts"]["traces"] == 0:
        raise typer.Exit(1)  # a run with failed units is not a success, whatever it printed


_SHORT_HEADERS = {
    "Pearson r": "r",
    "Error rate %": "err%",
    "Success rate %": "succ%",
    "QA acc. %": "QA%",
    "Tokens/video": "tokens",
    "Calls/video": "calls",
}


def _print_main_table(metrics: dict, oracle: bool = False) -> None:
    """summary.md's main table without SE, in 80 columns: no vertical rules, short headers,
    numbers never cut (a long method name wraps instead); n goes into the title."""
    from rich import box

    from rover.eval.summary import main_rows, prompt_cache_line

    headers, rows = main_rows(metrics, compact=True)
    n = sorted({r[-1] for r in rows})
    title = f"rover eval: mean over {'/'.join(n) or 0} videos per method (± SE: summary.md)"
    if oracle:
        title += "\nORACLE OUTPUT: oracle rows answer from ground truth, not a VLM"
    table = Table(title=title, box=box.SIMPLE_HEAD, padding=(0, 1), pad_edge=False)
    for h in headers[:-1]:
        is_name = h in ("Method", "View")
        table.add_column(
            _SHORT_HEADERS.get(h, h),
            no_wrap=not is_name,
            overflow="fold" if is_name else "ellipsis",
            justify="left" if is_name else "right",
            min_width=6 if is_name else None,
        )
    for r in rows:
        table.add_row(*(esc(cell) for cell in r[:-1]))  # method and backend names are data
    make_console().print(table)
    cache_line = prompt_cache_line(metrics)  # read from the cost table, as summary.md is
    if cache_line:
        make_console().print(esc(cache_line), highlight=False, soft_wrap=True)


def _short(n: int) -> str:
    """1234 -> '1.2k', 3400000 -> '3.4M' (the live line only; results print in full)."""
    for unit, size in (("M", 1_000_000), ("k", 1_000)):
        if n >= size:
            return f"{n / size:.1f}{unit}"
    return str(n)


def _build_report(run_dir: Path, err: Console) -> None:
    try:
        from rover.report import build_report
    except ImportError:
        err.print("the report builder is not available in this build; skipped --report")
        return
    path = build_report(run_dir)
    make_console().print(f"report: {esc(path)}")
