"""Run one method over the episodes of a source and keep what it said, resumably.

Layout of `--out`::

    annotate.json              the settings (a rerun with --resume must match them)
    traces/<episode>.json      one trace per finished episode (written atomically)
    errors.json                episodes that failed, with one line each
    frames.parquet             rebuilt from the traces at the end of every run
    episodes.parquet

An episode counts as done once its trace file exists; a rerun skips it. Inside an
unfinished episode, the calls already answered come back from the VLM layer's response
cache, so a killed run resumes without paying for any call twice.
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel

from rover.annotate.tables import (
    EPISODES_FILE,
    FRAMES_FILE,
    IN_PLACE_FILE,
    episode_row,
    episodes_table,
    frame_rows,
    frames_table,
    in_place_table,
    write_parquet_atomic,
)
from rover.errors import InputError, RoverError
from rover.eval.rundir import safe_name, write_json_atomic
from rover.io.source import SourceReader, open_source, require_tasks, sample_episode_ids
from rover.methods.trace import Trace
from rover.vlm.config import BackendConfig

SETTINGS_FILE = "annotate.json"
ERRORS_FILE = "errors.json"


class AnnotateSettings(BaseModel):
    """What decides the answers: a resumed run must use the same settings."""

    source: str
    method: str
    backend: str
    frames: int | None = None
    size: int | None = 256
    window: int | None = None
    view: str | None = None
    task: str | None = None
    success_threshold: float = 95.0
    model_path: str | None = None


@dataclass
class AnnotateOptions:
    """Everything `rover annotate` takes; `vlm` lets library users pass their own VLM."""

    source: str
    out: Path
    method: str = "rover"
    backend: str = "oracle"
    backend_config: BackendConfig = field(default_factory=BackendConfig)
    frames: int | None = None
    size: int | None = 256
    window: int | None = None
    view: str | None = None
    task: str | None = None
    episodes: list[str] | None = None  # ids or indices
    sample: int | None = None
    seed: int = 0
    success_threshold: float = 95.0
    concurrency: int = 4
    resume: bool = False
    in_place: bool = False
    model_path: Path | None = None  # clip-value: the local CLIP/SigLIP folder
    vlm: Any = None

    def settings(self) -> AnnotateSettings:
        return AnnotateSettings(
            source=self.source,
            method=self.method,
            backend=self.backend,
            frames=self.frames,
            size=self.size,
            window=self.window,
            view=self.view,
            task=self.task,
            success_threshold=self.success_threshold,
            model_path=None if self.model_path is None else str(self.model_path),
        )


@dataclass
class Planned:
    """The episodes to annotate: (episode_index, episode_id), and those already done."""

    reader: SourceReader
    episodes: list[tuple[int, str]]
    done: list[str]

    @property
    def pending(self) -> list[tuple[int, str]]:
        finished = set(self.done)
        return [(i, e) for i, e in self.episodes if e not in finished]


@dataclass
class AnnotateResult:
    episodes: int = 0
    annotated: int = 0
    skipped: int = 0
    failed: dict[str, str] = field(default_factory=dict)
    calls: int = 0
    tokens: int = 0
    frames_path: Path | None = None
    episodes_path: Path | None = None
    in_place_path: Path | None = None


def episode_indices(reader: SourceReader) -> dict[str, int]:
    """episode id -> episode_index: LeRobot's own index, else the position in the source."""
    ids = reader.episode_ids()
    if reader.kind == "lerobot":
        return {e: int(e.removeprefix("episode_")) for e in ids}
    return {e: i for i, e in enumerate(ids)}


def _pick(reader: SourceReader, opts: AnnotateOptions) -> list[tuple[int, str]]:
    index = episode_indices(reader)
    if opts.episodes and opts.sample is not None:
        raise InputError("give --episodes or --sample, not both")
    if opts.episodes:
        by_number = {str(i): e for e, i in index.items()}
        picked = []
        for want in opts.episodes:
            eid = want if want in index else by_number.get(want.strip())
            if eid is None:
                shown = ", ".join(list(index)[:5]) + (" ..." if len(index) > 5 else "")
                raise InputError(f"--episodes: no episode {want!r} in {opts.source}; {shown}")
            picked.append(eid)
        ids = [e for e in index if e in set(picked)]
    else:
        ids = sample_episode_ids(reader, opts.sample, opts.seed)
    return [(index[e], e) for e in ids]


def trace_path(out: Path, episode_id: str) -> Path:
    return Path(out) / "traces" / f"{safe_name(episode_id)}.json"


def plan_annotation(opts: AnnotateOptions) -> Planned:
    """Check every input and list the work, before any VLM is loaded or called.

    Raises:
        InputError: bad source, episode choice, missing task, an --out holding another
            annotation (or any annotation without --resume).
    """
    from rover.methods.registry import method_names

    if opts.method not in method_names():
        raise InputError(
            f"unknown method {opts.method!r}; valid methods: {', '.join(method_names())}"
        )
    if opts.method == "clip-value" and (
        opts.model_path is None or not Path(opts.model_path).is_dir()
    ):
        raise InputError("clip-value needs --model-path: a local CLIP or SigLIP folder")
    if opts.concurrency < 1:
        raise InputError(f"--concurrency must be at least 1, got {opts.concurrency}")
    if opts.frames is not None and opts.frames < 2:
        raise InputError(f"--frames must be at least 2, got {opts.frames}")
    reader = open_source(opts.source, task=opts.task, view=opts.view)
    if opts.in_place and reader.kind != "lerobot":
        raise InputError(
            f"--in-place writes beside a LeRobot dataset's meta/; "
            f"{opts.source} is a {reader.kind} source"
        )
    episodes = _pick(reader, opts)
    if not episodes:
        raise InputError(f"{opts.source}: no episodes to annotate")
    require_tasks(reader, [e for _, e in episodes], where=opts.source)
    out = Path(opts.out)
    saved = out / SETTINGS_FILE
    done: list[str] = []
    if saved.exists():
        if not opts.resume:
            raise InputError(
                f"--out {out} already holds an annotation; pass --resume to continue it "
                "or choose another --out"
            )
        before = AnnotateSettings.model_validate_json(saved.read_text())
        diff = [k for k, v in opts.settings().model_dump().items() if before.model_dump()[k] != v]
        if diff:
            raise InputError(
                f"--out {out} was annotated with other settings ({', '.join(diff)}); "
                "resume with the same ones or choose another --out"
            )
        done = [e for _, e in episodes if trace_path(out, e).exists()]
    elif out.exists() and any(out.iterdir()):
        raise InputError(f"--out {out} exists and is not an annotation folder; choose another")
    return Planned(reader, episodes, done)


OnEpisode = Callable[[str, Trace | None], None]


async def run_annotate(
    opts: AnnotateOptions, planned: Planned | None = None, on_episode: OnEpisode | None = None
) -> AnnotateResult:
    """Annotate every pending episode, then (re)write the tables from all traces."""
    from rover.methods.registry import NON_VLM_METHODS, get_method

    planned = planned or plan_annotation(opts)
    out = Path(opts.out)
    write_json_atomic(out / SETTINGS_FILE, opts.settings())
    vlm = opts.vlm
    if vlm is None and opts.method not in NON_VLM_METHODS:
        from rover.vlm.loader import load_vlm

        vlm = load_vlm(opts.backend, opts.backend_config)
    params = {"window": opts.window, "seed": opts.seed, "model_path": opts.model_path}
    result = AnnotateResult(episodes=len(planned.episodes), skipped=len(planned.done))
    errors = _read_errors(out)
    sem = asyncio.Semaphore(opts.concurrency)

    async def one(episode_id: str) -> None:
        async with sem:
            try:
                episode = await asyncio.to_thread(
                    planned.reader.read, episode_id, opts.frames, opts.size
                )
                trace = await get_method(opts.method, **params).run(episode, vlm)
                await asyncio.to_thread(trace.save, trace_path(out, episode_id))
            except RoverError as exc:
                errors[episode_id] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                if on_episode:
                    on_episode(episode_id, None)
                return
            errors.pop(episode_id, None)
            result.annotated += 1
            result.calls += trace.totals.calls
            result.tokens += trace.totals.total_tokens
            if on_episode:
                on_episode(episode_id, trace)

    try:
        await asyncio.gather(*(one(e) for _, e in planned.pending))
    finally:
        write_json_atomic(out / ERRORS_FILE, errors)
        close = getattr(vlm, "aclose", None)
        if close is not None:
            await close()
    result.failed = {e: m for e, m in errors.items() if e in {x for _, x in planned.episodes}}
    _write_tables(opts, planned, result)
    return result


def _read_errors(out: Path) -> dict[str, str]:
    path = out / ERRORS_FILE
    if not path.exists():
        return {}
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError:
        return {}
    return {str(k): str(v) for k, v in data.items()} if isinstance(data, dict) else {}


def _write_tables(opts: AnnotateOptions, planned: Planned, result: AnnotateResult) -> None:
    out = Path(opts.out)
    frames: list[dict[str, Any]] = []
    episodes: list[dict[str, Any]] = []
    for index, episode_id in planned.episodes:
        path = trace_path(out, episode_id)
        if not path.exists():
            continue
        trace = Trace.load(path)
        frames += frame_rows(trace, index)
        episodes.append(episode_row(trace, index, opts.success_threshold))
    result.frames_path = out / FRAMES_FILE
    result.episodes_path = out / EPISODES_FILE
    write_parquet_atomic(frames_table(frames), result.frames_path)
    write_parquet_atomic(episodes_table(episodes), result.episodes_path)
    if opts.in_place:
        offsets = planned.reader.global_offsets()  # type: ignore[attr-defined]
        result.in_place_path = planned.reader.path / IN_PLACE_FILE
        write_parquet_atomic(in_place_table(frames, offsets), result.in_place_path)
