"""Everything the report reads from a run directory, through `rover.run.store.RunStore`.

The report draws numbers, it never computes them: per-video scores and aggregates come
from the run's metrics.json (rescored by the one scorer when it is missing or outdated);
traces, verdicts and QA answers are read for the episode viewer only. Episodes' ground
truth and the frames the viewer shows are the run's own copies (`episodes/`, `frames/`),
so `rover report RUN` needs nothing outside RUN, on simulated and real data alike. An
older run without saved frames falls back to the dataset `run.json` names, if present.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from rover.episode import Episode
from rover.errors import InputError
from rover.io.dataset import DATASET_FILE, read_episode
from rover.methods.info import method_info, method_rank
from rover.methods.trace import Trace
from rover.run.store import RunStore, write_thumbs

log = logging.getLogger(__name__)

RUN_CONFIG = "run.json"  # written by `rover eval` (docs/evaluation.md)


@dataclass
class FrameVerdict:
    """The judge's verdict on one frame description: 'true', 'false' or 'inconclusive'."""

    verdict: str
    reason: str = ""


@dataclass
class QAResult:
    """One answered video question, with ground truth, as the evaluation recorded it."""

    question: str
    truth: bool
    predicted: bool | None
    truth_frame: int | None = None
    predicted_frame: int | None = None
    template: str = ""


@dataclass
class TraceEntry:
    """One scored (episode, variant): its trace, its metrics row and display labels."""

    trace: Trace
    variant_id: str
    path: Path
    row: dict[str, Any]
    label: str = ""  # the variant's label, e.g. "ROVER (window 6) · 60 frames"
    series: str = ""  # the same without frame count (for App. I figures)
    view: str = ""  # the camera the trace saw (a column, never part of the label)
    setting_view: str | None = None  # the view the variant asked for (None: each video's own)
    setting_frames: int | None = None  # the frame count it asked for (None: all frames)

    @property
    def key(self) -> tuple[str, str]:
        return self.variant_id, self.trace.episode_id


@dataclass
class RunData:
    """A run directory read into memory for drawing."""

    run_dir: Path
    store: RunStore
    config: dict[str, Any]
    metrics: dict[str, Any]
    entries: list[TraceEntry]
    dataset: Path | None = None
    episodes: dict[str, Episode] = field(default_factory=dict)
    verdicts: dict[tuple[str, str], dict[int, FrameVerdict]] = field(default_factory=dict)
    qa: dict[tuple[str, str], list[QAResult]] = field(default_factory=dict)

    @property
    def aggregates(self) -> list[dict[str, Any]]:
        return self.metrics.get("aggregates", [])

    @property
    def traces(self) -> list[Trace]:
        return [e.trace for e in self.entries]

    @property
    def backends(self) -> list[str]:
        """Every backend/model pair the traces were made with, e.g. 'oracle:oracle'."""
        return sorted({f"{t.backend}:{t.model}" if t.model else t.backend for t in self.traces})

    @property
    def oracle(self) -> bool:
        return any(t.oracle or t.backend == "oracle" for t in self.traces)

    def thumbs(self, episode_id: str, view: str | None) -> dict[int, Path]:
        """Original frame index -> small JPEG, from the run (or, for old runs, the dataset)."""
        found = self.store.thumbs(episode_id, view)
        if found or self.dataset is None:
            return found
        ep = self.episodes.get(episode_id)
        name = view if ep is not None and view in ep.view_names else (ep.view if ep else None)
        try:
            full = read_episode(self.dataset, episode_id, views=[name] if name else None)
        except InputError as exc:
            log.warning("no frames for %s: %s", episode_id, exc)
            return {}
        write_thumbs(self.run_dir, episode_id, full.view, full.frames(), full.frame_indices)
        return self.store.thumbs(episode_id, full.view)


def series_name(variant: dict[str, Any], backends: set[str]) -> str:
    """The variant's label without its frame count (the lines of an App. I figure)."""
    info = method_info(variant["method"])
    name = info.display
    w = variant.get("window")
    if w is not None and w != info.default_window:
        name += f" (window {w})"
    if len(backends) > 1:
        name += f" [{variant['backend']}]"
    return name


def load_run(run_dir: Path, dataset: Path | None = None) -> RunData:
    """Read a run directory written by `rover eval`; `dataset` is an old-run frame fallback."""
    run_dir = Path(run_dir)
    store = RunStore(run_dir)
    if not store.has_config:
        raise InputError(
            f"{run_dir}: no traces found (no {RUN_CONFIG}; expected a run directory "
            "written by rover eval)"
        )
    config = store.config()
    if not config.get("variants") or "episodes" not in config:
        raise InputError(
            f"{run_dir / RUN_CONFIG}: lists no variants or episodes (written by an older "
            "rover?); rerun rover eval with --resume to rewrite it"
        )
    metrics = store.metrics()
    variants = {v["id"]: v for v in metrics.get("variants", [])}
    backends = {v["backend"] for v in variants.values()}
    entries: list[TraceEntry] = []
    for row in metrics.get("per_trace", []):
        if row.get("error") is not None:
            continue
        path = store.stage_file("trace", row["episode_id"], row["variant"])
        try:
            trace = Trace.load(path)
        except (OSError, ValidationError, ValueError) as exc:
            log.warning("skipping %s: not a readable trace (%s)", path, exc)
            continue
        v = variants.get(row["variant"], {"method": trace.method, "backend": trace.backend})
        entries.append(
            TraceEntry(
                trace=trace,
                variant_id=row["variant"],
                path=path,
                row=row,
                label=row.get("label") or v.get("label") or row["variant"],
                series=series_name({**v, "method": row["method"]}, backends),
                view=str(row.get("view") or trace.view or ""),
                setting_view=v.get("view"),
                setting_frames=v.get("frames"),
            )
        )
    if not entries:
        raise InputError(f"{run_dir}: no traces found (no finished work unit in the run)")
    order = {vid: i for i, vid in enumerate(variants)}
    entries.sort(key=lambda e: (method_rank(e.trace.method), order.get(e.variant_id, 0)))
    run = RunData(
        run_dir=run_dir,
        store=store,
        config=config,
        metrics=metrics,
        entries=entries,
        dataset=_dataset(run_dir, config, dataset),
    )
    for eid in dict.fromkeys(e.trace.episode_id for e in entries):
        ep = store.episode(eid)
        if ep is not None:
            run.episodes[eid] = ep
    from rover.report.judgements import load_judgements

    load_judgements(run)
    return run


def _dataset(run_dir: Path, config: dict[str, Any], given: Path | None) -> Path | None:
    if given is not None:
        if not (Path(given) / DATASET_FILE).exists():
            raise InputError(f"{given}: not a rover dataset directory (no {DATASET_FILE})")
        return Path(given)
    c = config.get("dataset")
    if isinstance(c, str) and c:
        for base in (Path(c), run_dir / c):
            if (base / DATASET_FILE).exists():
                return base
    return None
