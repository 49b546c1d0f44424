"""Ground truth carried inside a LeRobot dataset that `rover export` wrote.

The export stores per-frame truth as data features (`progress`, `state_type`, `level`,
`source_frame_index`) and the rest in the episode table (`rover/subtasks`, `rover/events`,
`rover/qa`, `rover/facts`, ...). Reading it back rebuilds the `GroundTruth` exactly, so a
benchmark exported to LeRobot evaluates the same as the rover dataset it came from.
"""

from __future__ import annotations

import json
from typing import Any

from rover.episode import Event, FrameFacts, GroundTruth, QAItem, StateType, Subtask

TRUTH_COLUMNS = ["progress", "state_type", "level", "source_frame_index"]


def carries_truth(features: dict[str, Any], row: dict[str, Any]) -> bool:
    """True for episodes of a dataset written by `rover export --format lerobot`."""
    return "progress" in features and row.get("rover/progress_source") is not None


def rebuild_truth(
    row: dict[str, Any], data: dict[str, list], state_names: list[str]
) -> GroundTruth:
    """The whole episode's GroundTruth from its episode row and its data columns."""
    states = [int(s) for s in data["state_type"]]
    facts = row.get("rover/facts")
    return GroundTruth(
        progress=[float(p) for p in data["progress"]],
        state_type=None
        if any(s < 0 for s in states)
        else [StateType(state_names[s]) for s in states],
        subtasks=[Subtask(**s) for s in row.get("rover/subtasks") or []],
        events=[Event(**e) for e in row.get("rover/events") or []],
        facts=None if facts is None else [FrameFacts(**f) for f in json.loads(facts)],
        level=row.get("rover/level"),
        qa=[QAItem(**q) for q in row.get("rover/qa") or []],
        progress_source=row["rover/progress_source"],
    )
