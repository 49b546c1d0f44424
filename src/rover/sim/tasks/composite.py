"""Composite group: "restock" with robosuite PickPlace, two items into their bins."""

from __future__ import annotations

from rover.sim.levels import by_milestone, default_levels
from rover.sim.tasks._common import PICK_PLACE_ENDINGS, grasp_subtask, move_subtask, pick_place_qa
from rover.sim.tasks.base import GoalSpec, ObjectSpec, TaskSpec
from rover.sim.tasks.pick_place import BIN_OF, BODY_OF, bin_name

ITEMS = ("milk", "can")  # the far bin (the can's) last: no long reach back from it


def restock_task(items: tuple[str, ...] = ITEMS) -> TaskSpec:
    subtasks, qa = [], []
    for obj in items:
        target = f"in {bin_name(obj)}"
        subtasks += [
            grasp_subtask(f"pick up the {obj}", obj),
            move_subtask(f"place the {obj} {target}", obj, f"goal:bin_{obj}", f"placed:{obj}"),
        ]
        qa += [q for q in pick_place_qa(obj, target) if q.id != "did_contact"]
    levels = default_levels([[] for _ in subtasks])
    names = [f"Fail to pick up the {items[0]}"]
    for obj in items:
        names += [f"Pick up the {obj}", f"Place the {obj} in {bin_name(obj)}"]
    levels = [lv.model_copy(update={"name": n}) for lv, n in zip(levels, names, strict=True)]
    milestones = [f"{k}:{o}" for o in items for k in ("pick_up", "place")]
    listing = " and ".join(f"the {o} {'in ' + bin_name(o)}" for o in items)
    return TaskSpec(
        name="Restock",
        env_name="PickPlace",
        env_kwargs={"single_object_mode": 0},
        description=f"Restock the shelf: put {listing}.",
        group="composite",
        objects=[ObjectSpec(name=o, body=BODY_OF[o]) for o in items],
        # the other PickPlace items are moved out of the scene (as robosuite's
        # single-object mode does), so the two items are reachable without clutter
        clear_objects=[o.capitalize() for o in BIN_OF if o not in items],
        goals={f"bin_{o}": GoalSpec(kind="bin", object=o) for o in items},
        bins={o: BIN_OF[o] for o in items},
        subtasks=subtasks,
        levels=by_milestone(levels, milestones, PICK_PLACE_ENDINGS),
        milestones=milestones,
        qa_templates=qa,
        frames=60,
        expert="pick_place",
        max_expert_steps=900,
    )


TASKS = [restock_task()]
