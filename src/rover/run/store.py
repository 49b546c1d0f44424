"""One reader/writer for a run directory (layout: docs/evaluation.md#run-directory).

`rover eval` writes through `rover.eval.rundir.RunDir` (atomic files, the units log) and
this module adds what the views need: the frames a report shows, kept small in the run
(`frames/<episode>/<view>/<index>.jpg`), and typed reads of everything. `RunStore.metrics`
is the only way a view gets numbers: the stored metrics.json when it is current, else
the scorer's result computed from the run's own files, never numbers of its own.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image
from pydantic import ValidationError

from rover.episode import Episode
from rover.errors import InputError
from rover.eval.rundir import METRICS_FILE, RUN_FILE, safe_name
from rover.run import SCHEMA_VERSION
from rover.run.models import Metrics, RunConfig

log = logging.getLogger(__name__)

THUMB_SIDE = 112  # pixels, longest side: a filmstrip frame, ~3 kB as JPEG
FRAMES_DIR = "frames"


def write_thumbs(
    root: Path, episode_id: str, view: str, frames: np.ndarray, indices: list[int]
) -> int:
    """Save small JPEGs of `frames` (original indices `indices`) into the run; return count."""
    folder = Path(root) / FRAMES_DIR / safe_name(episode_id) / safe_name(view)
    folder.mkdir(parents=True, exist_ok=True)
    written = 0
    for ix, frame in zip(indices, frames, strict=True):
        path = folder / f"{int(ix):05d}.jpg"
        if path.exists():
            continue
        img = Image.fromarray(np.asarray(frame))
        img.thumbnail((THUMB_SIDE, THUMB_SIDE))
        tmp = path.with_name(path.name + ".tmp")
        img.save(tmp, format="JPEG", quality=80)
        tmp.replace(path)
        written += 1
    return written


class RunStore:
    """Typed, read-only access to a finished (or partial) run directory."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        if not self.root.is_dir():
            raise InputError(f"{self.root}: no such run directory")
        self._metrics: dict[str, Any] | None = None

    @property
    def has_config(self) -> bool:
        return (self.root / RUN_FILE).exists()

    def config(self) -> dict[str, Any]:
        path = self.root / RUN_FILE
        if not path.exists():
            return {}
        try:
            raw = json.loads(path.read_text())
            RunConfig.model_validate(raw)
        except (json.JSONDecodeError, UnicodeDecodeError, ValidationError) as exc:
            raise InputError(f"{path}: not a rover run configuration ({_why(exc)})") from exc
        return raw

    def metrics(self) -> dict[str, Any]:
        """metrics.json's data; rescored from the run's files when absent or outdated."""
        if self._metrics is not None:
            return self._metrics
        path = self.root / METRICS_FILE
        raw: dict[str, Any] | None = None
        if path.exists():
            try:
                raw = json.loads(path.read_text())
                Metrics.model_validate(raw)
            except (json.JSONDecodeError, UnicodeDecodeError, ValidationError) as exc:
                log.warning("%s unreadable (%s): rescoring the run", path, _why(exc))
                raw = None
        if raw is None or raw.get("schema_version") != SCHEMA_VERSION:
            if not self.has_config:
                raise InputError(f"{self.root}: no {RUN_FILE}; not a rover eval run directory")
            from rover.eval.results import compute_metrics
            from rover.eval.rundir import RunDir

            raw = compute_metrics(RunDir(self.root), self.config())
        self._metrics = raw
        return raw

    def episode(self, episode_id: str) -> Episode | None:
        """The episode's metadata and ground truth as the run saved it (no pixels)."""
        path = self.root / "episodes" / f"{safe_name(episode_id)}.json"
        if not path.exists():
            return None
        raw = json.loads(path.read_text())
        raw.pop("views", None)
        return Episode.model_validate(raw)

    def stage_file(self, stage: str, episode_id: str, variant_id: str) -> Path:
        folder = {"trace": "traces", "judge": "judgements", "qa": "qa"}[stage]
        return self.root / folder / safe_name(episode_id) / f"{variant_id}.json"

    def read_stage(self, stage: str, episode_id: str, variant_id: str) -> dict[str, Any] | None:
        path = self.stage_file(stage, episode_id, variant_id)
        if not path.exists():
            return None
        try:
            raw = json.loads(path.read_text())
        except (json.JSONDecodeError, OSError, UnicodeDecodeError) as exc:
            log.warning("skipping %s: %s", path, exc)
            return None
        return raw if isinstance(raw, dict) else None

    def thumbs(self, episode_id: str, view: str | None) -> dict[int, Path]:
        """Original frame index -> small JPEG saved by `rover eval` for this view."""
        base = self.root / FRAMES_DIR / safe_name(episode_id)
        folder = base / safe_name(view) if view else None
        if folder is None or not folder.is_dir():
            views = sorted(p for p in base.iterdir() if p.is_dir()) if base.is_dir() else []
            if not views:
                return {}
            folder = views[0]
        out = {}
        for p in sorted(folder.glob("*.jpg")):
            if p.stem.isdigit():
                out[int(p.stem)] = p
        return out


def _why(exc: Exception) -> str:
    if isinstance(exc, ValidationError):
        e = exc.errors()[0]
        return f"{'.'.join(map(str, e['loc']))}: {e['msg']}"
    return str(exc)
