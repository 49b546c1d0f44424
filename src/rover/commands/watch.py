"""`rover watch`: live progress over a folder that a camera process writes frames into.

    rover watch /tmp/cam --task "open the drawer" --backend openai:gpt-4o --out live.json

Every new complete frame (PNG/JPEG, in file-name order; see `rover.stream.folder`) is
pushed to a `RoverStream`, and one status line shows frames seen, progress, the current
subtask and the calls made. It stops when the task's line of reasoning ends complete,
on Ctrl-C (after the frame being reasoned about), or after `--idle-timeout` seconds
without a new frame, and writes the trace of what it saw to `--out`.
"""

from __future__ import annotations

import asyncio
import contextlib
import signal
import time
from pathlib import Path
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.live import Live
from rich.text import Text

from rover.commands.reason import MAX_SIZE, MIN_SIZE, _summary
from rover.console import line as safe_line
from rover.console import make_console
from rover.errors import InputError
from rover.methods.trace import Trace
from rover.paths import check_output_file
from rover.stream.folder import FolderFrames
from rover.stream.rover_stream import FrameEstimate, RoverStream
from rover.vlm import cli_options as vo

WIDTH = 80  # the status line never wraps on a standard terminal
BAR = 12


def status_line(est: FrameEstimate | None, frames: int, calls: int, width: int = WIDTH) -> Text:
    """`  12 frames [####      ]  45.0%  grasp the can > lift  31 calls`, cut to `width`."""
    progress = 0.0 if est is None else est.progress
    filled = max(0, min(BAR, round(BAR * progress / 100)))
    head = f"{frames:>4} frames [{'#' * filled}{' ' * (BAR - filled)}] {progress:5.1f}%  "
    tail = f"  {calls} calls" + ("  done" if est is not None and est.complete else "")
    room = max(width - len(head) - len(tail), 0)
    path = safe_line(" > ".join(est.subtask_path) if est and est.subtask_path else "(task)")
    if len(path) > room:  # keep the innermost subtask, the part that changes
        path = "…" + path[-(room - 1) :] if room > 1 else ""
    text = Text(head, style="bold")
    text.append(path)  # model text: a plain Text, never markup
    text.append(tail, style="dim")
    return text


async def _follow(
    stream: RoverStream,
    folder: FolderFrames,
    show,
    size: int | None,
    idle_timeout: float,
    poll: float,
    stop: asyncio.Event,
) -> str:
    """Push frames until complete, stopped or idle; returns why it stopped."""
    from rover.io.frames import resize_long_side

    last_new = time.monotonic()
    calls = 0
    while True:
        for fr in folder.poll():
            pixels = fr.pixels if size is None else resize_long_side(fr.pixels[None], size)[0]
            est = await stream.push(pixels, index=fr.index)
            calls += est.calls
            show(est, stream.frames_pushed, calls)
            last_new = time.monotonic()
            if est.complete:
                return "task complete"
            if stop.is_set():
                return "interrupted"
        if stop.is_set():
            return "interrupted"
        if time.monotonic() - last_new >= idle_timeout:
            return f"no new frame for {idle_timeout:g} s"
        try:
            await asyncio.wait_for(stop.wait(), timeout=poll)
        except TimeoutError:
            pass


def run_watch(
    folder: Path,
    *,
    task: str,
    backend: str | None = None,
    out: Path = Path("trace.json"),
    size: int | None = 256,
    window: int | None = None,
    idle_timeout: float = 30.0,
    poll: float = 0.2,
    config_options: dict | None = None,
    console: Console | None = None,
    summary: Console | None = None,
) -> Trace | None:
    """Everything `rover watch` does, callable from Python; None when no frame arrived."""
    from rover.vlm.loader import load_vlm

    if not task.strip():
        raise InputError('rover watch needs the task: --task "..."')
    if idle_timeout <= 0 or poll <= 0:
        raise InputError("--idle-timeout and --poll must be positive (seconds)")
    if size is not None and not MIN_SIZE <= size <= MAX_SIZE:
        raise InputError(f"--size must be between {MIN_SIZE} and {MAX_SIZE} px, got {size}")
    out = check_output_file(out)
    frames = FolderFrames(folder)
    backend = vo.resolve_backend(backend)
    if backend.split(":", 1)[0] == "oracle":
        raise InputError(
            "the oracle answers from simulator ground truth, which a folder of camera frames "
            "does not have: use a real backend (openai:, gemini:, hf:) or replay:"
        )
    vlm = load_vlm(backend, vo.config_from_options(**(config_options or {})))
    params: dict[str, Any] = {} if window is None else {"window": window}
    stream = RoverStream(task, vlm, episode_id=Path(folder).resolve().name, **params)
    console = console or make_console(stderr=True)
    summary = summary or make_console()
    live_tty = console.is_terminal
    width = min(console.width, WIDTH) if live_tty else WIDTH

    async def main() -> tuple[str, Trace | None]:
        stop = asyncio.Event()
        loop = asyncio.get_running_loop()

        def on_sigint() -> None:  # the first Ctrl-C stops after the current frame
            stop.set()
            loop.remove_signal_handler(signal.SIGINT)  # a second one aborts

        loop.add_signal_handler(signal.SIGINT, on_sigint)
        try:
            # a terminal gets one line updated in place; a log gets one line per frame
            live = Live(status_line(None, 0, 0, width), console=console) if live_tty else None

            def show(est: FrameEstimate, n: int, calls: int) -> None:
                text = status_line(est, n, calls, width)
                if live is not None:
                    live.update(text)
                else:
                    console.print(text, soft_wrap=True)

            with live if live is not None else contextlib.nullcontext():
                why = await _follow(stream, frames, show, size, idle_timeout, poll, stop)
            trace = await stream.trace() if stream.frames_pushed else None
            return why, trace
        finally:
            loop.remove_signal_handler(signal.SIGINT)
            close = getattr(vlm, "aclose", None)
            if close is not None:
                await close()

    why, trace = asyncio.run(main())
    note = f" ({len(frames.skipped)} late or unreadable files skipped)" if frames.skipped else ""
    summary.print(f"stopped: {why}{note}", highlight=False, markup=False)
    if trace is None:
        summary.print("no frame arrived: no trace written", highlight=False, markup=False)
        return None
    trace.save(out)
    _summary(summary, trace, out)
    return trace


def register(app: typer.Typer) -> None:
    @app.command("watch")
    def watch(
        folder: Annotated[Path, typer.Argument(help="Folder a camera process writes frames into.")],
        task: Annotated[str, typer.Option("--task", help="Task text (required).")] = "",
        backend: Annotated[
            str | None,
            typer.Option(
                "--backend", "--vlm", help=vo.VLM_HELP + " (default: $ROVER_BACKEND / config)"
            ),
        ] = None,
        out: Annotated[Path, typer.Option("--out", "-o", help="Where to write the trace JSON.")] = (
            Path("trace.json")
        ),
        idle_timeout: Annotated[
            float, typer.Option("--idle-timeout", help="Stop after this many s without a frame.")
        ] = 30.0,
        poll: Annotated[
            float, typer.Option("--poll", help="Seconds between looks at the folder.")
        ] = 0.2,
        size: Annotated[int, typer.Option("--size", help="Long side of frames in px.")] = 256,
        window: Annotated[
            int | None, typer.Option("--window", help="ROVER window size K (default 3).")
        ] = None,
        seed: Annotated[int | None, typer.Option("--seed", help="Sampling seed.")] = None,
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
        """Follow a folder of camera frames live; print progress; write the trace."""
        run_watch(
            folder,
            task=task,
            backend=backend,
            out=out,
            size=size,
            window=window,
            idle_timeout=idle_timeout,
            poll=poll,
            config_options={
                "seed": seed,
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
            },
        )
