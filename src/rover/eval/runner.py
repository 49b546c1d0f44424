"""The evaluation runner: every (episode, variant) through method, judge and QA, resumably.

Episodes run concurrently on one asyncio loop, at most `concurrency` at a time; inside an
episode its variants run concurrently too, and each backend bounds its own calls in
flight. A work unit is one (episode, variant) with three stages, trace -> judgement ->
QA answers; each stage's file is written atomically the moment it is done, so a run
killed at any point keeps all finished stages and `--resume` does only the rest. Video
decoding and file writes go through `asyncio.to_thread` so the loop never stalls.
A unit that fails (corrupt video, backend error, a bug in a method) is recorded under
`errors/` and the run goes on; a later resume retries it.
"""

from __future__ import annotations

import asyncio
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field

from rover.episode import Episode
from rover.errors import InputError, RoverError
from rover.eval.episodes import (
    EpisodeRef,
    dataset_refs,
    is_real_source,
    load_for_variants,
    source_refs,
    variant_episode,
)
from rover.eval.judge import llm_judge_trace, rule_judge_trace
from rover.eval.live import Counted
from rover.eval.qa import llm_answer_trace, rule_answer_trace
from rover.eval.runconfig import run_config
from rover.eval.rundir import RunDir, write_json_atomic
from rover.eval.variants import Variant, expand_variants
from rover.methods.trace import Trace
from rover.vlm.config import BackendConfig
from rover.vlm.types import EncodedImage, ImageEncoding

OFF = ("none", "off", "skip")
PRE_ENCODE_BUDGET = 3072  # images; below the EncodedImage memo's capacity (4096)


class EvalOptions(BaseModel):
    """Everything `rover eval` was asked to do (the CLI builds it; library users may too)."""

    dataset: Path | None = None
    sources: list[str] = Field(default_factory=list)
    methods: list[str]
    backends: list[str]
    judge: str = "rule"
    answerer: str = "rule"
    frames: list[int | None] = Field(default_factory=lambda: [None])
    windows: list[int | None] = Field(default_factory=lambda: [None])
    views: list[str | None] = Field(default_factory=lambda: [None])
    concurrency: int = 16
    limit: int | None = None
    episodes: int | None = None  # sample this many per source
    seed: int = 0
    out: Path
    resume: bool = False
    model_path: Path | None = None  # clip-value: local CLIP/SigLIP folder
    backend_config: BackendConfig = Field(default_factory=BackendConfig)
    command: list[str] = Field(default_factory=list)


@dataclass
class RunState:
    """Counters the progress display reads."""

    episodes_total: int = 0
    episodes_done: int = 0
    units_total: int = 0
    units_done: int = 0
    units_skipped: int = 0
    calls: int = 0
    tokens: int = 0
    errors: int = 0
    last_error: str = ""
    extra: dict[str, Any] = field(default_factory=dict)


OnUpdate = Callable[[RunState], None]


def episode_refs(opts: EvalOptions) -> list[EpisodeRef]:
    if (opts.dataset is None) == (not opts.sources):
        raise InputError("give exactly one of --dataset DIR or --source SPEC")
    if opts.dataset is not None:
        refs = dataset_refs(opts.dataset, opts.episodes, opts.seed)
    else:
        refs = source_refs(opts.sources, opts.episodes, opts.seed)
    if opts.dataset is not None:
        _check_views(opts, refs)
    if opts.limit is not None:
        if opts.limit <= 0:
            raise InputError(f"--limit must be positive, got {opts.limit}")
        refs = refs[: opts.limit]
    return refs


def _check_views(opts: EvalOptions, refs: list[EpisodeRef]) -> None:
    """Unknown --views fail up front (one line), not as one error per episode."""
    from rover.io.dataset import read_dataset_info, read_episode

    wanted = [v for v in opts.views if v]
    if not wanted or not refs:
        return
    known = set(read_dataset_info(opts.dataset).views)
    known |= set(read_episode(opts.dataset, refs[0].source_id, load_frames=False).view_names)
    for v in wanted:
        if v not in known:
            raise InputError(
                f"--views: no view {v!r} in {opts.dataset}; views: {', '.join(sorted(known))}"
            )


def check_methods(methods: list[str]) -> None:
    from rover.methods.registry import get_method

    for m in methods:
        get_method(m)  # unknown names raise InputError listing the valid ones


def _load_backend(spec: str, config: BackendConfig) -> Any:
    from rover.vlm import load_vlm

    return load_vlm(spec, config)


def _warm_up() -> None:
    """Pay one-time costs (token encodings) here, not on the event loop mid-run."""
    try:
        from rover.vlm.tokens import estimate_text_tokens

        estimate_text_tokens("warm up")
    except Exception:  # noqa: BLE001 - only an optimisation
        pass


class Runner:
    """One evaluation run; `await runner.run()` does all pending work."""

    def __init__(
        self,
        opts: EvalOptions,
        config: dict[str, Any],
        refs: list[EpisodeRef],
        variants: list[Variant],
        on_update: OnUpdate | None = None,
        vlms: dict[str, Any] | None = None,
        executor: Any = None,
    ) -> None:
        self.opts = opts
        # rover.exec: None or a local one runs units here; a remote one (Ray) elsewhere
        self.executor = executor
        self.remote = bool(getattr(executor, "remote", False))
        if self.remote and vlms:
            raise InputError(
                "ready VLM objects run in this process only: load backends by spec for a "
                "remote executor, or use executor local"
            )
        self.rundir = RunDir(opts.out)
        self.config = config
        self.refs = refs
        self.variants = variants
        self.on_update = on_update or (lambda s: None)
        self.state = RunState(episodes_total=len(refs), units_total=len(refs) * len(variants))
        self.stages = ["trace"]
        if opts.judge.lower() not in OFF:
            self.stages.append("judge")
        if opts.answerer.lower() not in OFF:
            self.stages.append("qa")
        given = self._given = vlms or {}
        self.vlms = {
            b: given.get(b) or _load_backend(b, opts.backend_config) for b in opts.backends
        }
        self.judge_vlm = self._aux(opts.judge, "--judge")
        self.answer_vlm = self._aux(opts.answerer, "--answerer")
        # every finished call counts at once (the display moves during long episodes)
        self.vlms = {b: Counted(v, self._count_call) for b, v in self.vlms.items()}
        if self.judge_vlm is not None:
            self.judge_vlm = Counted(self.judge_vlm, self._count_call)
        if self.answer_vlm is not None:
            self.answer_vlm = Counted(self.answer_vlm, self._count_call)

    def _count_call(self, tokens: int) -> None:
        self.state.calls += 1
        self.state.tokens += tokens
        self.on_update(self.state)

    def _aux(self, spec: str, option: str) -> Any:
        if spec.lower() in OFF or spec.lower() == "rule":
            return None
        if spec.strip().lower() == "oracle":
            raise InputError(
                f"{spec!r} cannot judge or answer questions (it only answers method prompts); "
                "use 'rule' or an LLM spec for --judge / --answerer"
            )
        if spec in self.vlms or spec in self._given:
            return self.vlms.get(spec) or self._given[spec]
        config = self.opts.backend_config.model_copy(update={"flip_prob": 0.0, "jitter": 0.0})
        try:
            return _load_backend(spec, config)
        except InputError as exc:  # name the option: the spec alone does not say which one
            raise InputError(f"{option}: {exc}") from exc

    def _pending(self, ref: EpisodeRef) -> list[Variant]:
        return [
            v
            for v in self.variants
            if not all(self.rundir.done(s, ref.id, v.id) for s in self.stages)
        ]

    async def run(self) -> RunState:
        sem = asyncio.Semaphore(max(1, self.opts.concurrency))
        self.on_update(self.state)
        try:
            await asyncio.gather(*(self._episode(ref, sem) for ref in self.refs))
        finally:
            self.rundir.close()
        await asyncio.to_thread(self.rundir.write_errors_file)
        return self.state

    async def _episode(self, ref: EpisodeRef, sem: asyncio.Semaphore) -> None:
        pending = self._pending(ref)
        skipped = len(self.variants) - len(pending)
        self.state.units_done += skipped
        self.state.units_skipped += skipped
        if not pending:
            self.state.episodes_done += 1
            self.on_update(self.state)
            return
        async with sem:
            try:
                meta, loaded = await asyncio.to_thread(self._load, ref, pending)
                if not self.rundir.episode_path(ref.id).exists():
                    await asyncio.to_thread(
                        write_json_atomic, self.rundir.episode_path(ref.id), meta
                    )
            except Exception as exc:  # noqa: BLE001 - one bad episode must not end the run
                for v in pending:
                    await self._fail(ref, v, "load", exc)
                self.state.episodes_done += 1
                self.on_update(self.state)
                return
            if self.remote:  # every unit of this episode as a task; results written here
                from rover.exec.eval_unit import remote_units

                await remote_units(self, ref, meta, loaded, pending)
            else:
                await asyncio.gather(*(self._unit(ref, meta, loaded, v) for v in pending))
        self.state.episodes_done += 1
        self.on_update(self.state)

    def _load(self, ref: EpisodeRef, pending: list[Variant]) -> tuple[Episode, Episode]:
        """Decode the episode and JPEG-encode its frames, off the event loop (a thread).

        Methods encode each frame they send through `EncodedImage.from_any`, which memoises
        by pixels and settings; encoding here first means the loop only finds them ready.
        """
        saved = self.rundir.episode_path(ref.id)
        if saved.exists() and all(self.rundir.done("trace", ref.id, v.id) for v in pending):
            # only judging / QA is left: ground truth is enough, no need to decode video
            meta = Episode.model_validate_json(saved.read_text())
            return meta, meta
        meta, loaded = load_for_variants(ref, pending)
        from rover.run.store import write_thumbs

        for name, arr in loaded.views.items():  # the run keeps the frames a report shows
            write_thumbs(self.rundir.root, ref.id, name, arr, loaded.frame_indices)
        encodings: dict[str, ImageEncoding] = {}
        for v in pending:
            enc = getattr(self.vlms[v.backend], "image_encoding", None) or ImageEncoding()
            encodings[enc.model_dump_json()] = enc
        total = sum(len(arr) for arr in loaded.views.values()) * len(encodings)
        # the memo holds a few thousand images: pre-encode only what fits for every episode
        # in flight, else later episodes would evict earlier ones' frames before use
        if not self.remote and total <= PRE_ENCODE_BUDGET // max(1, self.opts.concurrency):
            for arr in loaded.views.values():
                for enc in encodings.values():
                    for frame in arr:
                        EncodedImage.from_any(frame, enc)
        return meta, loaded

    async def _fail(self, ref: EpisodeRef, v: Variant, stage: str, exc: BaseException) -> None:
        await self.record_failure(ref, v, stage, failure_message(exc))

    async def record_failure(self, ref: EpisodeRef, v: Variant, stage: str, msg: str) -> None:
        """Record a failed unit (`msg` already scrubbed): errors/, units.jsonl, counters."""
        await asyncio.to_thread(self.rundir.record_error, ref.id, v.id, stage, msg)
        self.rundir.log_unit(ref.id, v.id, stage, "error", error=msg[:300])
        self.state.errors += 1
        self.state.units_done += 1
        self.state.last_error = f"{ref.id} {v.label}: {msg.split(' | ')[0][:120]}"
        self.on_update(self.state)

    async def _unit(self, ref: EpisodeRef, meta: Episode, loaded: Episode, v: Variant) -> None:
        stage = "trace"
        try:
            episode = variant_episode(loaded, meta.frame_indices, v)
            trace = await self._trace(ref, episode, v)
            stage = "judge"
            if "judge" in self.stages and not self.rundir.done("judge", ref.id, v.id):
                await self._judge(ref, episode, trace, v)
            stage = "qa"
            if "qa" in self.stages and not self.rundir.done("qa", ref.id, v.id):
                await self._qa(ref, episode, trace, v)
        except Exception as exc:  # noqa: BLE001 - recorded, the run goes on
            await self._fail(ref, v, stage, exc)
            return
        await asyncio.to_thread(self.rundir.clear_error, ref.id, v.id)
        self.state.units_done += 1
        self.on_update(self.state)

    async def _trace(self, ref: EpisodeRef, episode: Episode, v: Variant) -> Trace:
        path = self.rundir.trace_path(ref.id, v.id)
        if path.exists():
            return await asyncio.to_thread(Trace.load, path)
        from rover.methods.registry import get_method

        method = get_method(v.method, **v.params)
        vlm = self.vlms[v.backend].bind(episode)
        self.rundir.log_unit(ref.id, v.id, "trace", "start")
        trace = await method.run(episode, vlm)
        if trace.totals.calls == 0 and trace.calls:
            trace.totals = trace.compute_totals()
        await asyncio.to_thread(trace.save, path)
        self.rundir.log_unit(ref.id, v.id, "trace", "done", calls=trace.totals.calls)
        return trace

    async def _judge(self, ref: EpisodeRef, episode: Episode, trace: Trace, v: Variant) -> None:
        await self._scoring_stage(
            "judge",
            ref,
            episode,
            trace,
            v,
            rule=rule_judge_trace,
            llm=llm_judge_trace,
            vlm=self.judge_vlm,
            spec=self.opts.judge,
        )

    async def _qa(self, ref: EpisodeRef, episode: Episode, trace: Trace, v: Variant) -> None:
        await self._scoring_stage(
            "qa",
            ref,
            episode,
            trace,
            v,
            rule=rule_answer_trace,
            llm=llm_answer_trace,
            vlm=self.answer_vlm,
            spec=self.opts.answerer,
        )

    async def _scoring_stage(
        self,
        stage: str,
        ref: EpisodeRef,
        episode: Episode,
        trace: Trace,
        v: Variant,
        *,
        rule,
        llm,
        vlm,
        spec: str,
    ) -> None:
        """Score a finished trace (judge or QA) offline by rule or through an LLM."""
        self.rundir.log_unit(ref.id, v.id, stage, "start")
        if vlm is None:
            result = await asyncio.to_thread(rule, trace, episode, v.id)
        else:
            result = await llm(trace, episode, v.id, vlm.bind(episode), spec)
        await asyncio.to_thread(
            write_json_atomic, self.rundir.stage_path(stage, ref.id, v.id), result
        )
        self.rundir.log_unit(ref.id, v.id, stage, "done", calls=result.calls)


def failure_message(exc: BaseException) -> str:
    """One scrubbed line for a failed unit: the message, plus a traceback tail for bugs."""
    msg = str(exc) if isinstance(exc, RoverError) else f"{type(exc).__name__}: {exc}"
    if not isinstance(exc, RoverError):
        tb = traceback.format_exception(exc)
        msg += " | " + "".join(tb[-3:]).strip().replace("\n", " | ")[-600:]
    from rover.vlm.keys import scrub

    return scrub(msg)


def method_params(opts: EvalOptions) -> dict[str, dict[str, Any]]:
    """Fixed per-method parameters from the options (clip-value's local model)."""
    if opts.model_path is None:
        return {}
    return {"clip-value": {"model_path": str(opts.model_path)}}


def build_variants(opts: EvalOptions) -> list[Variant]:
    return expand_variants(
        opts.methods, opts.backends, opts.frames, opts.windows, opts.views, method_params(opts)
    )


def prepare_run(
    opts: EvalOptions,
    on_update: OnUpdate | None = None,
    vlms: dict[str, Any] | None = None,
    executor: Any = None,
) -> Runner:
    """Check every input, load the backends and set up the run directory (no VLM calls).

    `vlms` maps backend specs to ready VLM objects, for library users with their own VLM
    class (anything with `complete` and `bind`); other specs go through `load_vlm`.
    `executor` (see `rover.exec`) runs the work units; None: on this process's event loop.

    Raises:
        InputError: unknown method, bad sweep value, missing dataset, non-empty --out...
    """
    check_methods(opts.methods)
    if "clip-value" in opts.methods:
        if opts.model_path is None:
            raise InputError("clip-value needs --model-path: a local CLIP or SigLIP folder")
        if not Path(opts.model_path).is_dir():
            raise InputError(f"--model-path {opts.model_path}: no such folder")
    variants = build_variants(opts)
    refs = episode_refs(opts)
    real = [r for r in refs if is_real_source(r.origin)]
    if real and any(b.strip().lower() == "oracle" for b in opts.backends):
        # recorded videos carry frame-number truth only, which the oracle would echo back
        # as a perfect score: refused here, before any work, not once per work unit
        raise InputError(
            f"the oracle answers from simulator ground truth and {real[0].origin} has none: "
            "use a real backend (openai:, gemini:, hf:) or replay:"
        )
    _warm_up()
    config = run_config(opts, variants, refs)
    # backends load before anything is written, so a bad spec leaves no half-made run dir
    runner = Runner(opts, config, refs, variants, on_update, vlms, executor)
    RunDir(opts.out).prepare(config, opts.resume)
    return runner


async def finish_run(runner: Runner) -> tuple[RunState, dict]:
    """Do all pending work, then write metrics.json and summary.md."""
    from rover.eval.results import compute_metrics, write_results

    state = await runner.run()
    metrics = await asyncio.to_thread(compute_metrics, runner.rundir, runner.config)
    await asyncio.to_thread(write_results, runner.rundir, metrics)
    return state, metrics


async def run_eval(
    opts: EvalOptions, on_update: OnUpdate | None = None, executor: Any = None
) -> tuple[RunState, dict]:
    """Run (or resume) an evaluation; returns the final counters and metrics.json's data."""
    runner = await asyncio.to_thread(prepare_run, opts, on_update, None, executor)
    return await finish_run(runner)
