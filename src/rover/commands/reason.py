"""`rover reason`: run one reasoning method on one video and write its trace.

    rover reason clip.mp4 --task "open the drawer" --method rover --backend openai:gpt-4o \\
        --frames 30 --out trace.json

The video can be anything `rover.io.source.load_episode` reads (MP4, a folder of numbered
frames, a dataset episode, lerobot:/rlds:/hdf5: specs). A live bar shows the frame being
reasoned about, the current subtask path and the last progress value; the summary says
how many calls and tokens it took and where the trace went.
"""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

from rover.console import esc, make_console
from rover.console import line as safe_line
from rover.errors import InputError
from rover.methods.base import StepInfo
from rover.methods.registry import NON_VLM_METHODS, get_method, method_names
from rover.methods.trace import Trace
from rover.paths import check_output_file
from rover.vlm import cli_options as vo

MIN_SIZE, MAX_SIZE = 16, 8192  # --size bounds (px, long side)


def _load(video: str, frames: int | None, size: int | None, task: str | None, view: str | None):
    from rover.io.source import load_episode

    if frames is not None and frames <= 0:
        raise InputError(f"--frames must be positive, got {frames}")
    if size is not None and not MIN_SIZE <= size <= MAX_SIZE:
        raise InputError(f"--size must be between {MIN_SIZE} and {MAX_SIZE} px, got {size}")
    episode = load_episode(video, frames=frames, size=size, task=task, view=view)
    if frames is not None and episode.num_frames < frames:
        raise InputError(
            f"--frames {frames}: {safe_line(video)} has only {episode.num_frames} frames"
        )
    if task:
        episode = episode.model_copy(update={"task": task})
    if not episode.task.strip():
        raise InputError(f'{video} carries no task description; pass --task "..."')
    return episode


def run_reason(
    video: str,
    *,
    method: str = "rover",
    backend: str | None = None,
    out: Path = Path("trace.json"),
    task: str | None = None,
    frames: int | None = None,
    size: int | None = 256,
    window: int | None = None,
    view: str | None = None,
    seed: int | None = None,
    model_path: Path | None = None,
    config_options: dict | None = None,
    console: Console | None = None,
    summary: Console | None = None,
) -> Trace:
    """Everything `rover reason` does, callable from Python (and from tests)."""
    from rover.vlm.loader import load_vlm

    console = console or make_console(stderr=True)
    if method not in method_names():
        raise InputError(f"unknown method {method!r}; valid methods: {', '.join(method_names())}")
    out = check_output_file(out)  # before any decoding or paid call
    if method not in NON_VLM_METHODS:
        backend = vo.resolve_backend(backend)  # before any decoding: a one-line refusal
    episode = _load(video, frames, size, task, view)
    params = {"window": window, "seed": seed, "model_path": model_path}
    m = get_method(method, **params)
    opts = dict(config_options or {})
    if seed is not None:
        opts["seed"] = seed
    vlm = None if method in NON_VLM_METHODS else load_vlm(backend, vo.config_from_options(**opts))

    n = episode.num_frames
    with Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("{task.fields[path]}", markup=False),  # model text: never markup
        TextColumn("{task.fields[last]}", markup=False),
        TimeElapsedColumn(),
        console=console,
        transient=True,
    ) as bar:
        job = bar.add_task(f"{method} frame", total=n, path="", last="")

        def on_step(info: StepInfo) -> None:
            path = " > ".join(info.subtask_path) or "(task)"
            last = "" if info.progress is None else f"{info.progress:.0f}%"
            bar.update(
                job,
                completed=min(info.position + 1, n),
                path=safe_line(path)[-60:],
                last=f"{last}  calls {info.calls}",
            )

        trace = asyncio.run(_run(m, episode, vlm, on_step))
    trace.save(out)
    _summary(summary or make_console(), trace, out)
    return trace


async def _run(method, episode, vlm, on_step) -> Trace:
    try:
        return await method.run(episode, vlm, on_step)
    finally:
        close = getattr(vlm, "aclose", None)
        if close is not None:
            await close()


def _summary(console: Console, trace: Trace, out: Path) -> None:
    t = trace.totals
    final = trace.progress()[-1] if trace.frames else 0.0
    label = " [bold yellow]ORACLE[/] (answers from ground truth, not a VLM)" if trace.oracle else ""
    # the provider's prompt-prefix cache, not rover's response cache counted in "calls"
    cached = (
        f"; {t.cached_prompt_tokens:,} in the provider's prefix cache"
        if t.cached_prompt_tokens
        else ""
    )
    console.print(
        f"[bold]{esc(trace.method)}[/] on {esc(trace.episode_id)}: {trace.num_frames} frames, "
        f"{t.calls} calls ({t.cached_calls} cached), {t.total_tokens:,} tokens "
        f"({t.prompt_tokens:,} prompt + {t.completion_tokens:,} completion{cached}), "
        f"{t.parse_failures} parse failures, final progress {final:.0f}%{label}",
        highlight=False,
        soft_wrap=True,
    )
    console.print(f"trace written to {esc(out)}", highlight=False, soft_wrap=True)


def register(app: typer.Typer) -> None:
    @app.command("reason")
    def reason(
        video: Annotated[str, typer.Argument(help="Video, frame folder, dataset episode or spec.")],
        task: Annotated[
            str | None, typer.Option("--task", help="Task text (default: the episode's own).")
        ] = None,
        method: Annotated[
            str, typer.Option("--method", "-m", help=f"One of: {', '.join(method_names())}.")
        ] = "rover",
        backend: Annotated[
            str | None,
            typer.Option(
                "--backend", "--vlm", help=vo.VLM_HELP + " (default: $ROVER_BACKEND / config)"
            ),
        ] = None,
        out: Annotated[Path, typer.Option("--out", "-o", help="Where to write the trace JSON.")] = (
            Path("trace.json")
        ),
        frames: Annotated[
            int | None, typer.Option("--frames", help="Sample N frames evenly (first, last kept).")
        ] = None,
        size: Annotated[int, typer.Option("--size", help="Long side of frames in px.")] = 256,
        window: Annotated[
            int | None, typer.Option("--window", help="ROVER window size K (default 3).")
        ] = None,
        view: Annotated[str | None, typer.Option("--view", help="Camera view to use.")] = None,
        seed: Annotated[
            int | None, typer.Option("--seed", help="Seed for GVL shuffles and oracle noise.")
        ] = None,
        model_path: Annotated[
            Path | None, typer.Option("--model-path", help="clip-value: local CLIP/SigLIP folder.")
        ] = None,
        flip_prob: Annotated[
            float | None, typer.Option("--flip-prob", help="Oracle: chance to flip each claim.")
        ] = None,
        jitter: Annotated[
            float | None, typer.Option("--jitter", help="Oracle: progress noise std (points).")
        ] = None,
        cache: vo.CacheOpt = None,
        no_cache: vo.NoCacheOpt = False,
        record: vo.RecordOpt = None,
        concurrency: vo.ConcurrencyOpt = None,
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
        """Reason over one video with one method and write the trace (JSON)."""
        run_reason(
            video,
            method=method,
            backend=backend,
            out=out,
            task=task,
            frames=frames,
            size=size,
            window=window,
            view=view,
            seed=seed,
            model_path=model_path,
            config_options={
                "cache": cache,
                "no_cache": no_cache,
                "record": record,
                "concurrency": concurrency,
                "timeout": timeout,
                "max_retries": max_retries,
                "api_key_env": api_key_env,
                "detail": detail,
                "token_rule": token_rule,
                "max_side": max_side,
                "temperature": temperature,
                "max_tokens": max_tokens,
                "device": device,
                "flip_prob": flip_prob,
                "jitter": jitter,
            },
        )
