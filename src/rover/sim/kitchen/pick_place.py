"""The kitchen suite's pick-and-place tasks (paper App. B, Table 4; Table 5; App. C.3; App. N).

Each task moves one free item of a category (`rover.sim.kitchen.items`; the instance is
drawn per seed and recorded in ``episode.json`` under ``extra.scene.item``) from a start
region to a goal region (`rover.sim.kitchen.regions`): the counter beside the fixture
in use, the sink basin, the stove's cooktop. As for robosuite's PickPlace tasks
(`rover.sim.tasks.pick_place`), the object-centric subtasks are "pick up the item" (the
fingers come to it; ends when it is lifted in the grasp) and "place it" (the item is
carried to the goal region's point; ends when it rests there, let go), the levels are
Table 5's seven pick-and-place levels, the questions App. C.3's, and the expert the
tabletop pick-and-place script. The facts report the region as ``inside``/``on``, so a
hold that ends with the item resting in the goal region is a ``place`` and any other a
``drop`` (`rover.sim.facts`).

The item is named by its category ("the vegetable") in the instruction, the subtasks and
the questions, which stay fixed per task while the instance changes with the seed.
"""

from __future__ import annotations

from rover.sim.kitchen.items import host_body
from rover.sim.kitchen.regions import OPENINGS
from rover.sim.tasks._common import pick_place_protocol
from rover.sim.tasks.base import GoalSpec, ObjectSpec, TaskSpec

SUITE = "kitchen"
# where a region's goal point is taken from: a fixture site, or the counter spot site
# the env moves per scene (plus a world offset: the sink's point sits in the basin's
# front half, clear of the spout hanging over its back)
GOAL_POINT = {
    "sink": ("Sink_basin", (-0.05, 0.0, 0.0)),
    "stove": ("Stove_burner", (0.0, 0.0, 0.0)),
    "counter": ("kitchen_counter_goal", (0.0, 0.0, 0.0)),
    "microwave": ("Microwave_interior", (0.0, 0.0, 0.0)),
    "coffee machine": ("Coffee_slot", (0.0, 0.0, 0.0)),
    "cabinet": ("Cabinet_inside", (0.0, 0.0, 0.0)),
}
# how the instruction names a region as a start ("from ...") and as a goal
FROM = {"sink": "the sink", "stove": "the stove", "counter": "the counter"}
TO = {"sink": "in the sink", "stove": "on the stove", "counter": "on the counter"}
FROM["microwave"], TO["microwave"] = "the microwave", "in the microwave"
FROM["coffee machine"] = "the coffee machine"
TO["coffee machine"] = "under the coffee machine's spout"
FIXTURE_OF = {"sink": "Sink", "stove": "Stove", "microwave": "Microwave"}
FIXTURE_OF["coffee machine"] = "Coffee"
FIXTURE_OF["cabinet"] = "Cabinet"
FROM["cabinet"], TO["cabinet"] = "the cabinet", "in the cabinet"
# regions behind a door: it stands open (rad) in the scene, as in RoboCasa's tasks
OPEN_DOOR = {"microwave": 1.85, "cabinet": 1.7}


def _paraphrases(obj: str, start: str, goal: str) -> list[str]:
    return [
        f"Take the {obj} from {FROM[start]} and put it {TO[goal]}.",
        f"Move the {obj} from {FROM[start]} to {FROM[goal]}.",
        f"Pick up the {obj} that is {TO[start]} and set it down {TO[goal]}.",
    ]


def pick_place(name: str, category: str, start: str, goal: str) -> TaskSpec:
    """One kitchen pick-and-place task: an item of `category` from `start` to `goal`."""
    fixture = FIXTURE_OF[goal if start == "counter" else start]
    obj = category
    target = TO[goal]
    site, offset = GOAL_POINT[goal]
    kwargs = {
        "fixture": fixture,
        "part": next(iter(_parts(fixture))),
        "item": category,
        "start": start,
        "goal": goal,
    }
    where = goal if start == "counter" else start
    if where in OPEN_DOOR:
        kwargs.update(part="door", start_q=OPEN_DOOR[where])
    proto = pick_place_protocol(obj, target, "goal:region")
    if where in OPENINGS:  # reached through an opening: the hand points into it
        proto["expert"] = "kitchen_forward"
    return TaskSpec(
        name=f"{SUITE}.{name}",
        env_name="RoverKitchen",
        env_kwargs=kwargs,
        description=f"Pick the {obj} from {FROM[start]} and place it {target}.",
        paraphrases=_paraphrases(obj, start, goal),
        suite=SUITE,
        objects=[ObjectSpec(name=obj, body=host_body(category))],
        goals={"region": GoalSpec(kind="body", body=site, offset=offset)},
        **proto,
    )


def _parts(fixture: str) -> dict[str, str]:
    from rover.sim.kitchen.fixtures import FIXTURES

    return FIXTURES[fixture].joints


TASKS: list[TaskSpec] = [
    pick_place("PickPlaceCabToCounter", "pantry item", "cabinet", "counter"),
    pick_place("PickPlaceCounterToCab", "pantry item", "counter", "cabinet"),
    pick_place("PickPlaceCounterToSink", "vegetable", "counter", "sink"),
    pick_place("PickPlaceSinkToCounter", "vegetable", "sink", "counter"),
    pick_place("PickPlaceCounterToStove", "vegetable", "counter", "stove"),
    pick_place("PickPlaceStoveToCounter", "vegetable", "stove", "counter"),
    pick_place("PickPlaceCounterToMicrowave", "food container", "counter", "microwave"),
    pick_place("PickPlaceMicrowaveToCounter", "food container", "microwave", "counter"),
    pick_place("CoffeeSetupMug", "mug", "counter", "coffee machine"),
    pick_place("CoffeeServeMug", "mug", "coffee machine", "counter"),
]
