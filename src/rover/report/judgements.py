"""Judge verdicts (Task 2) and video-QA answers (Task 3), as `rover eval` recorded them.

Files (docs/evaluation.md): `judgements/<episode>/<variant>.json` with one verdict per
frame, and `qa/<episode>/<variant>.json` with one answer per question. The report never
judges anything itself; it only shows what the run holds, so an unreadable file is
skipped with a warning rather than failing the whole report.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rover.report.run import RunData

log = logging.getLogger(__name__)


def load_judgements(run: RunData) -> None:
    """Fill `run.verdicts` and `run.qa` for every trace whose files exist."""
    from rover.report.run import FrameVerdict, QAResult

    for entry in run.entries:
        eid, vid = entry.trace.episode_id, entry.variant_id
        raw = _read(run.run_dir / "judgements" / eid / f"{vid}.json")
        if raw is not None:
            verdicts = {}
            for v in raw.get("verdicts", []):
                if isinstance(v, dict) and isinstance(v.get("index"), int):
                    verdicts[v["index"]] = FrameVerdict(
                        str(v.get("verdict", "inconclusive")), str(v.get("reason") or "")
                    )
            run.verdicts[entry.key] = verdicts
        raw = _read(run.run_dir / "qa" / eid / f"{vid}.json")
        if raw is not None:
            run.qa[entry.key] = [
                QAResult(
                    question=str(a.get("question", "")),
                    truth=bool(a.get("truth")),
                    predicted=a.get("predicted"),
                    truth_frame=a.get("truth_frame"),
                    predicted_frame=a.get("predicted_frame"),
                    template=str(a.get("template") or ""),
                )
                for a in raw.get("answers", [])
                if isinstance(a, dict)
            ]


def _read(path: Path) -> dict[str, Any] | None:
    if not path.exists():
        return None
    try:
        raw = json.loads(path.read_text())
    except (json.JSONDecodeError, OSError, UnicodeDecodeError) as exc:
        log.warning("skipping %s: %s", path, exc)
        return None
    return raw if isinstance(raw, dict) else None
