"""Task registry: one declarative `TaskSpec` per benchmark task (see `base.py`)."""

from __future__ import annotations

from rover.errors import InputError
from rover.sim.kitchen.tasks import TASKS as KITCHEN_TASKS
from rover.sim.tasks import articulated, composite, doors, pick, pick_place, stack
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

_REGISTRY: dict[str, TaskSpec] = {
    t.name: t
    for module in (pick, pick_place, stack, doors, articulated, composite)
    for t in module.TASKS
}
# the kitchen suite (rover.sim.kitchen): names carry the suite, "kitchen.OpenDrawer"
_REGISTRY.update({t.name: t for t in KITCHEN_TASKS})
SUITES = ("tabletop", "kitchen")

__all__ = [
    "GoalSpec",
    "ObjectSpec",
    "QATemplate",
    "SubtaskSpec",
    "SUITES",
    "TaskSpec",
    "get_task",
    "task_names",
]


def task_names(suite: str = "tabletop") -> list[str]:
    """Registered task names of one suite ("tabletop", "kitchen" or "all"), in order.

    The default stays the tabletop suite (robosuite's tasks), as before the kitchen.
    """
    if suite != "all" and suite not in SUITES:
        raise InputError(f"unknown suite {suite!r}; valid suites: all, {', '.join(SUITES)}")
    return [n for n, t in _REGISTRY.items() if suite in ("all", t.suite)]


def get_task(name: str) -> TaskSpec:
    """The spec of a task; unknown names raise InputError listing the valid ones."""
    try:
        return _REGISTRY[name]
    except KeyError:
        valid = ", ".join(task_names("all"))
        raise InputError(f"unknown task {name!r}; valid tasks: {valid}") from None
