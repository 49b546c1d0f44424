"""Task registry: one declarative `TaskSpec` per benchmark task (see `base.py`)."""

from __future__ import annotations

from rover.errors import InputError
from rover.sim.tasks import articulated, composite, doors, pick, pick_place, stack
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

_REGISTRY: dict[str, TaskSpec] = {
    t.name: t
    for module in (pick, pick_place, stack, doors, articulated, composite)
    for t in module.TASKS
}

__all__ = [
    "GoalSpec",
    "ObjectSpec",
    "QATemplate",
    "SubtaskSpec",
    "TaskSpec",
    "get_task",
    "task_names",
]


def task_names() -> list[str]:
    """Registered task names, in registry order (pick, pick-and-place, ..., composite)."""
    return list(_REGISTRY)


def get_task(name: str) -> TaskSpec:
    """The spec of a task; unknown names raise InputError listing the valid ones."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise InputError(f"unknown task {name!r}; valid tasks: {', '.join(task_names())}") from None
