"""Everything the report reads from a run directory, in one place.

The layout is the evaluation runner's (docs/evaluation.md): `run.json`,
`traces/<episode>/<variant>.json`, `judgements/...` and `qa/...` beside them. The report
depends on as little of it as it can: every `*.json` under the run that parses as a
`Trace` is a trace (its file stem is its variant id), and the dataset is the one
`run.json` names (or one given explicitly). With traces plus the dataset's episodes the
report recomputes every progress and cost number itself; judge verdicts and video-QA
answers are shown when the run recorded them.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from rover.episode import Episode
from rover.errors import InputError
from rover.io.dataset import DATASET_FILE, episode_ids, read_episode
from rover.methods.trace import Trace

log = logging.getLogger(__name__)

RUN_CONFIG = "run.json"  # written by `rover eval` (docs/evaluation.md)

DISPLAY_NAMES = {
    "rover": "ROVER",
    "rover-no-window": "ROVER w/o window",
    "rover-no-recursion": "ROVER w/o recursion",
    "gvl": "GVL",
    "gvl-single": "GVL (single call)",
    "temporal-concat": "TemporalConcat",
    "local-concat": "LocalConcat",
    "video-concat": "VideoConcat",
    "clip-value": "CLIP value",
}
METHOD_ORDER = list(DISPLAY_NAMES)
DEFAULT_WINDOW = 3


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
    truth_frame: int | None = None  # original frame index (or position) the event happened
    predicted_frame: int | None = None
    template: str = ""


@dataclass
class TraceEntry:
    """One trace file: the trace, its variant id (file stem) and its display labels."""

    trace: Trace
    variant_id: str
    path: Path
    label: str = ""  # full configuration name, e.g. "ROVER (window 6) · 60 frames"
    series: str = ""  # the same without frame count and view (for App. H / I figures)

    @property
    def key(self) -> tuple[str, str]:
        return self.variant_id, self.trace.episode_id


@dataclass
class RunData:
    """A run directory read into memory: traces, episodes (metadata), optional judgements."""

    run_dir: Path
    entries: list[TraceEntry]
    dataset: Path | None
    episodes: dict[str, Episode] = field(default_factory=dict)
    # (variant id, episode id) -> original frame index -> verdict
    verdicts: dict[tuple[str, str], dict[int, FrameVerdict]] = field(default_factory=dict)
    qa: dict[tuple[str, str], list[QAResult]] = field(default_factory=dict)
    config: dict[str, Any] = field(default_factory=dict)
    # metrics.json's long-form aggregate rows, for the frame-level strata (App. G) that
    # only the evaluation computes; empty when the run has no metrics.json
    aggregates: list[dict[str, Any]] = field(default_factory=list)

    @property
    def traces(self) -> list[Trace]:
        return [e.trace for e in self.entries]

    @property
    def backends(self) -> list[str]:
        """Every backend/model pair the traces were made with, e.g. 'oracle (oracle)'."""
        return sorted({f"{t.backend}:{t.model}" if t.model else t.backend for t in self.traces})

    @property
    def oracle(self) -> bool:
        return any(t.oracle or t.backend == "oracle" for t in self.traces)

    def episode_frames(self, episode_id: str, view: str | None) -> Episode | None:
        """The episode with one view's pixels, or None when the dataset is not at hand."""
        if self.dataset is None or episode_id not in self.episodes:
            return None
        ep = self.episodes[episode_id]
        name = view if view in ep.view_names else ep.view
        try:
            return read_episode(self.dataset, episode_id, views=[name])
        except InputError as exc:
            log.warning("no frames for %s: %s", episode_id, exc)
            return None


def _label_entries(entries: list[TraceEntry]) -> None:
    """Name configurations by what actually varies in this run, nothing more."""
    traces = [e.trace for e in entries]
    multi_model = len({(t.backend, t.model) for t in traces}) > 1
    multi_frames = len({t.num_frames for t in traces}) > 1
    multi_view = len({t.view for t in traces}) > 1
    for e in entries:
        t = e.trace
        name = DISPLAY_NAMES.get(t.method, t.method)
        window = t.params.get("window")
        if t.method in ("rover", "rover-no-recursion") and window not in (None, DEFAULT_WINDOW):
            name = f"{name} (window {window})"
        if multi_model:
            name = f"{name} [{t.model or t.backend}]"
        e.series = name
        if multi_frames:
            name = f"{name} · {t.num_frames} frames"
        if multi_view:
            name = f"{name} · {t.view or 'default view'}"
        e.label = name


def entry_sort_key(e: TraceEntry) -> tuple[int, int, str, int, str]:
    t = e.trace
    order = METHOD_ORDER.index(t.method) if t.method in METHOD_ORDER else len(METHOD_ORDER)
    window = t.params.get("window")
    return (
        order,
        int(window) if isinstance(window, int) else 0,
        t.model,
        t.num_frames,
        t.view or "",
    )


def load_run(run_dir: Path, dataset: Path | None = None) -> RunData:
    """Read a run directory; `dataset` overrides the dataset the run's config names."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: no such run directory")
    entries = _load_traces(run_dir)
    if not entries:
        raise InputError(f"{run_dir}: no traces found (expected traces/**/*.json from rover eval)")
    entries.sort(key=entry_sort_key)
    _label_entries(entries)
    config = _load_config(run_dir)
    ds = Path(dataset) if dataset is not None else _dataset_from_config(run_dir, config)
    run = RunData(run_dir=run_dir, entries=entries, dataset=ds, config=config)
    run.aggregates = _load_aggregates(run_dir / "metrics.json")
    if ds is not None:
        if not (ds / DATASET_FILE).exists():
            raise InputError(f"{ds}: not a rover dataset directory (no {DATASET_FILE})")
        wanted = {e.trace.episode_id for e in entries}
        for eid in episode_ids(ds):
            if eid in wanted:
                run.episodes[eid] = read_episode(ds, eid, load_frames=False)
    else:
        log.warning("dataset of %s not found: ground-truth figures are skipped", run_dir)
    from rover.report.judgements import load_judgements

    load_judgements(run)
    return run


def _load_traces(run_dir: Path) -> list[TraceEntry]:
    traces: list[TraceEntry] = []
    for path in sorted(run_dir.rglob("*.json")):
        if path.relative_to(run_dir).parts[0] in ("report", "judgements", "qa", "errors"):
            continue
        try:
            raw = json.loads(path.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError, OSError):
            continue
        if not (isinstance(raw, dict) and "method" in raw and "frames" in raw):
            continue
        try:
            traces.append(TraceEntry(Trace.model_validate(raw), path.stem, path))
        except ValidationError as exc:
            log.warning("skipping %s: not a valid trace (%s)", path, exc.errors()[0]["msg"])
    return traces


def _load_config(run_dir: Path) -> dict[str, Any]:
    path = run_dir / RUN_CONFIG
    if not path.exists():
        return {}
    try:
        raw = json.loads(path.read_text())
    except json.JSONDecodeError:
        log.warning("skipping %s: not valid JSON", path)
        return {}
    return raw if isinstance(raw, dict) else {}


def _load_aggregates(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    try:
        rows = json.loads(path.read_text()).get("aggregates", [])
    except (json.JSONDecodeError, AttributeError, OSError):
        log.warning("skipping %s: not readable as metrics", path)
        return []
    return [r for r in rows if isinstance(r, dict)]


def _dataset_from_config(run_dir: Path, config: dict[str, Any]) -> Path | None:
    """The dataset a run was made from: run.json's `dataset` (absolute or run-relative)."""
    c = config.get("dataset")
    if isinstance(c, str) and c:
        for base in (Path(c), run_dir / c):
            if (base / DATASET_FILE).exists():
                return base
    if (run_dir / "dataset" / DATASET_FILE).exists():
        return run_dir / "dataset"
    return None
