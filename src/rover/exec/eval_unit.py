"""`rover eval` work units as tasks on a remote executor (Ray).

A unit (episode, variant) runs its pending stages on a worker — trace, then judge and QA
answers — with the same functions the in-process runner calls, and returns the objects
the runner would have saved; the driver saves them (`Trace.save`, `write_json_atomic`),
so the files are the local run's, whichever node did the work, and the driver's disk
is the only one written. A unit's stages land together when its task returns (locally
each stage lands as it finishes), so a killed run redoes at most the units in flight.

Backends are loaded on the worker from their spec and the `BackendConfig`, which holds
the *name* of the key variable, never a key: workers read keys from their own
environment. Each remote endpoint gets one cluster-wide call budget (an `EndpointBudget`
actor with `BackendConfig.concurrency` permits, i.e. `--calls-in-flight`), so adding
nodes never sends an endpoint more calls at once than one local run would.
"""

from __future__ import annotations

import asyncio
import threading
from dataclasses import dataclass, field
from typing import Any

from rover.episode import Episode
from rover.eval.variants import Variant
from rover.methods.trace import Trace
from rover.vlm.config import BackendConfig

OFF = ("none", "off", "skip")
LOCAL_SPECS = ("oracle", "replay:", "hf:")  # answered on the worker: no endpoint to protect


def needs_budget(spec: str) -> bool:
    """True for specs that call a server (openai:, gemini:, ...), not oracle/replay/hf."""
    s = spec.strip().lower()
    return not any(s == p or (p.endswith(":") and s.startswith(p)) for p in LOCAL_SPECS)


@dataclass
class UnitJob:
    """Everything a worker needs for one unit, by value (no paths into the run dir)."""

    episode_id: str
    frame_indices: list[int]
    variant: Variant
    stages: list[str]  # scoring stages still to do ("judge", "qa")
    judge: str
    answerer: str
    backends: list[str]
    config: BackendConfig
    trace: Trace | None = None  # the saved trace when only scoring is left
    budgets: dict[str, Any] = field(default_factory=dict)  # spec -> EndpointBudget handle


@dataclass
class UnitResult:
    trace: Trace | None = None  # a new trace (None: the job's own was reused)
    judgement: Any = None
    qa: Any = None
    failed_stage: str | None = None
    error: str | None = None  # scrubbed, as the local runner records it
    calls: int = 0
    tokens: int = 0


# ------------------------------------------------------------------ on a worker
class Budgeted:
    """A VLM whose calls each hold a permit of the endpoint's cluster-wide budget."""

    def __init__(self, inner: Any, budget: Any) -> None:
        self._inner = inner
        self._budget = budget

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)

    def bind(self, episode: Any) -> Budgeted:
        return Budgeted(self._inner.bind(episode), self._budget)

    async def complete(self, *args: Any, **kwargs: Any) -> Any:
        await self._budget.acquire.remote()
        try:
            return await self._inner.complete(*args, **kwargs)
        finally:
            await self._budget.release.remote()


_LOOP: asyncio.AbstractEventLoop | None = None
_LOCK = threading.Lock()
_VLMS: dict[tuple[str, str], Any] = {}


def _loop() -> asyncio.AbstractEventLoop:
    """This worker's one event loop (a thread): backends and their clients stay on it."""
    global _LOOP
    with _LOCK:
        if _LOOP is None:
            from rover.eval.runner import _warm_up

            _warm_up()  # one-time costs before the first call's latency is measured
            loop = asyncio.new_event_loop()
            threading.Thread(target=loop.run_forever, name="rover-units", daemon=True).start()
            _LOOP = loop
    return _LOOP


def _vlm(spec: str, config: BackendConfig) -> Any:
    """The worker's backend for `spec` (loaded once per process and config)."""
    from rover.vlm import load_vlm

    key = (spec, config.model_dump_json())
    if key not in _VLMS:
        _VLMS[key] = load_vlm(spec, config)
    return _VLMS[key]


def unit_job(job: UnitJob, loaded: Episode) -> UnitResult:
    """Run one unit's pending stages (a Ray task body)."""
    return asyncio.run_coroutine_threadsafe(_unit(job, loaded), _loop()).result()


async def _unit(job: UnitJob, loaded: Episode) -> UnitResult:
    from rover.eval.episodes import variant_episode
    from rover.eval.live import Counted
    from rover.eval.runner import failure_message

    result = UnitResult()

    def count(tokens: int) -> None:
        result.calls += 1
        result.tokens += tokens

    def wrap(spec: str, config: BackendConfig) -> Any:
        vlm = _vlm(spec, config)
        if spec in job.budgets:
            vlm = Budgeted(vlm, job.budgets[spec])
        return Counted(vlm, count)

    v = job.variant
    stage = "trace"
    try:
        episode = variant_episode(loaded, job.frame_indices, v)
        trace = job.trace
        if trace is None:
            from rover.methods.registry import get_method

            method = get_method(v.method, **v.params)
            trace = await method.run(episode, wrap(v.backend, job.config).bind(episode))
            if trace.totals.calls == 0 and trace.calls:
                trace.totals = trace.compute_totals()
            result.trace = trace
        for stage in job.stages:
            value = await _score(stage, job, trace, episode, wrap)
            setattr(result, "judgement" if stage == "judge" else "qa", value)
    except Exception as exc:  # noqa: BLE001 - recorded by the driver, the run goes on
        result.failed_stage, result.error = stage, failure_message(exc)
    return result


async def _score(stage: str, job: UnitJob, trace: Trace, episode: Episode, wrap) -> Any:
    """Judge or answer QA for a finished trace, by rule or through an LLM (as locally)."""
    from rover.eval.judge import llm_judge_trace, rule_judge_trace
    from rover.eval.qa import llm_answer_trace, rule_answer_trace

    spec = job.judge if stage == "judge" else job.answerer
    rule, llm = (
        (rule_judge_trace, llm_judge_trace)
        if stage == "judge"
        else (rule_answer_trace, llm_answer_trace)
    )
    if spec.lower() in OFF or spec.lower() == "rule":
        return await asyncio.to_thread(rule, trace, episode, job.variant.id)
    config = job.config  # a backend of the run serves as judge with its own config
    if spec not in job.backends:
        config = config.model_copy(update={"flip_prob": 0.0, "jitter": 0.0})
    return await llm(trace, episode, job.variant.id, wrap(spec, config).bind(episode), spec)


# ------------------------------------------------------------------ on the driver
def _budgets(runner: Any) -> dict[str, Any]:
    specs = [*runner.opts.backends, runner.opts.judge, runner.opts.answerer]
    permits = runner.opts.backend_config.concurrency
    out = {}
    for spec in specs:
        low = spec.lower()
        if low in OFF or low == "rule" or not needs_budget(spec):
            continue
        out[spec] = runner.executor.budget(spec, permits)
    return out


async def remote_units(
    runner: Any, ref: Any, meta: Episode, loaded: Episode, pending: list[Variant]
) -> None:
    """Every pending variant of one episode as a task; frames go to the object store once."""
    shared = await asyncio.to_thread(runner.executor.put, loaded)
    budgets = _budgets(runner)
    await asyncio.gather(*(_remote_unit(runner, ref, meta, shared, v, budgets) for v in pending))


async def _remote_unit(
    runner: Any, ref: Any, meta: Episode, shared: Any, v: Variant, budgets: dict[str, Any]
) -> None:
    from rover.eval.rundir import write_json_atomic
    from rover.exec.ray_cluster import EVAL_UNIT_CPUS

    rd, state = runner.rundir, runner.state
    trace = None
    if rd.done("trace", ref.id, v.id):
        trace = await asyncio.to_thread(Trace.load, rd.trace_path(ref.id, v.id))
    todo = [s for s in runner.stages if s != "trace" and not rd.done(s, ref.id, v.id)]
    first = "trace" if trace is None else todo[0]
    opts = runner.opts
    job = UnitJob(
        episode_id=ref.id,
        frame_indices=list(meta.frame_indices),
        variant=v,
        stages=todo,
        judge=opts.judge,
        answerer=opts.answerer,
        backends=list(opts.backends),
        config=opts.backend_config,
        trace=trace,
        budgets=budgets,
    )
    rd.log_unit(ref.id, v.id, first, "start")
    try:
        result = await runner.executor.call(unit_job, job, shared, num_cpus=EVAL_UNIT_CPUS)
    except Exception as exc:  # noqa: BLE001 - the task itself was lost (a node died...)
        await runner._fail(ref, v, first, exc)
        return
    state.calls += result.calls
    state.tokens += result.tokens
    if result.trace is not None:
        await asyncio.to_thread(result.trace.save, rd.trace_path(ref.id, v.id))
        rd.log_unit(ref.id, v.id, "trace", "done", calls=result.trace.totals.calls)
    for stage, value in (("judge", result.judgement), ("qa", result.qa)):
        if value is not None:
            await asyncio.to_thread(write_json_atomic, rd.stage_path(stage, ref.id, v.id), value)
            rd.log_unit(ref.id, v.id, stage, "done", calls=value.calls)
    if result.error is not None:
        await runner.record_failure(ref, v, result.failed_stage or first, result.error)
        return
    await asyncio.to_thread(rd.clear_error, ref.id, v.id)
    state.units_done += 1
    runner.on_update(state)
