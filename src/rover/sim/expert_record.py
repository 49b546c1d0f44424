"""Measured scripted-expert success per task, as `benchmarks/expert_success.py --write` left it.

`rover tasks` shows expert success, and a number shown must be one that was measured:
the benchmark writes each task's result (successes, seeds, mean steps, date) into
``expert_success.json`` beside this module, and readers only ever show what is recorded
there ("not measured" otherwise). Each record carries a fingerprint of what the expert
ran against (the spec fields its run depends on and, for a kitchen task, its fixture's
MJCF), so a record made before those changed is reported as stale rather than passed
off as current; a change of levels or questions leaves it standing. Changes to the
expert scripts themselves are not fingerprinted: rerun the benchmark with --write after
changing one.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import tempfile
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from rover.sim.tasks.base import TaskSpec

RECORD = Path(__file__).resolve().parent / "expert_success.json"
ABOUT = (
    "Scripted-expert success per task on seeds first_seed..first_seed+seeds-1, written by "
    "`python benchmarks/expert_success.py --write` (do not edit by hand)."
)


# the spec fields a scripted expert's run depends on (its scene, script, step budget and
# success test); levels, questions and wordings do not change whether it succeeds
EXPERT_FIELDS = {
    "env_name",
    "env_kwargs",
    "objects",
    "goals",
    "subtasks",
    "expert",
    "max_expert_steps",
    "bins",
    "clear_objects",
}


def fingerprint(spec: TaskSpec) -> str:
    """12 hex digits over what the expert ran against: the spec fields it depends on
    (`EXPERT_FIELDS`) and, for a kitchen task, its fixture's MJCF."""
    h = hashlib.sha256(json.dumps(spec.model_dump(include=EXPERT_FIELDS), sort_keys=True).encode())
    fixture = spec.env_kwargs.get("fixture") if spec.suite == "kitchen" else None
    if fixture:
        from rover.sim.kitchen.fixtures import FIXTURES

        if fixture in FIXTURES:
            h.update(FIXTURES[fixture].xml.read_bytes())
    return h.hexdigest()[:12]


def read_records(path: Path | None = None) -> dict[str, dict[str, Any]]:
    """Task name -> its last recorded measurement ({} when nothing was measured)."""
    path = path or RECORD
    if not path.exists():
        return {}
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    tasks = data.get("tasks") if isinstance(data, dict) else None
    return tasks if isinstance(tasks, dict) else {}


def write_record(
    spec: TaskSpec,
    successes: int,
    seeds: int,
    mean_steps: float,
    first_seed: int = 0,
    path: Path | None = None,
) -> dict[str, Any]:
    """Record one task's measurement, keeping the other tasks' (safe across processes)."""
    path = path or RECORD
    entry = {
        "successes": int(successes),
        "seeds": int(seeds),
        "first_seed": int(first_seed),
        "mean_steps": round(float(mean_steps), 1),
        "date": datetime.now(UTC).strftime("%Y-%m-%d"),
        "fingerprint": fingerprint(spec),
    }
    key = hashlib.sha256(str(path).encode()).hexdigest()[:12]
    lock = Path(tempfile.gettempdir()) / f"rover-expert-success-{key}.lock"
    with open(lock, "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        tasks = read_records(path)
        tasks[spec.name] = entry
        body = {"about": ABOUT, "tasks": dict(sorted(tasks.items()))}
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps(body, indent=1) + "\n", encoding="utf-8")
        tmp.replace(path)
    return entry


def expert_success(spec: TaskSpec, records: dict[str, dict[str, Any]] | None = None) -> dict:
    """What can be said about a task's expert success, for display.

    Returns ``{"measured": False}`` when nothing is recorded, else the record plus
    ``rate`` and ``stale`` (True when the task or its fixture changed since).
    """
    rec = (read_records() if records is None else records).get(spec.name)
    if not isinstance(rec, dict) or not rec.get("seeds"):
        return {"measured": False}
    out = {**rec, "measured": True, "rate": rec["successes"] / rec["seeds"]}
    out["stale"] = rec.get("fingerprint") != fingerprint(spec)
    return out
