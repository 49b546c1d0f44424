"""Judge verdicts (Task 2) and video-QA answers (Task 3), as `rover eval` recorded them.

Read for the episode viewer only: which frames were judged true / false / inconclusive,
and which questions were answered how. Their *scores* come from metrics.json. An
unreadable file is skipped with a warning rather than failing the whole report.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rover.report.run import RunData


def load_judgements(run: RunData) -> None:
    """Fill `run.verdicts` and `run.qa` for every trace whose files exist."""
    from rover.report.run import FrameVerdict, QAResult

    for entry in run.entries:
        eid, vid = entry.trace.episode_id, entry.variant_id
        raw = run.store.read_stage("judge", eid, vid)
        if raw is not None:
            verdicts = {}
            for v in raw.get("verdicts", []):
                if isinstance(v, dict) and isinstance(v.get("index"), int):
                    verdicts[v["index"]] = FrameVerdict(
                        str(v.get("verdict", "inconclusive")), str(v.get("reason") or "")
                    )
            run.verdicts[entry.key] = verdicts
        raw = run.store.read_stage("qa", eid, vid)
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
