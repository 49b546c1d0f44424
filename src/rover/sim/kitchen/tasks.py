"""The kitchen suite's task specs (paper App. B, Tables 4 and 5; App. C.3; App. N).

Each task names one kitchen fixture part (`rover.sim.kitchen.fixtures`); the env is
``RoverKitchen`` with that part in reach and the rest of the kitchen drawn per seed. The
object-centric subtasks are the tabletop fixtures' (grasp or touch the part, then move it
to its target), levels follow Table 5's row for the task's group and the QA templates
App. C.3's. Registry names carry the suite ("kitchen.OpenDrawer"): the tabletop suite
already has an OpenDrawer and a CloseDrawer, and episode ids, demo files and caches are
keyed by the task name.
"""

from __future__ import annotations

import numpy as np

from rover.sim.kitchen.composites import TASKS as COMPOSITE_TASKS
from rover.sim.kitchen.forward_composites import TASKS as FORWARD_COMPOSITE_TASKS
from rover.sim.kitchen.language import PARAPHRASES
from rover.sim.kitchen.pick_place import TASKS as PICK_PLACE_TASKS
from rover.sim.kitchen.thawing import microwave_thawing
from rover.sim.levels import by_milestone
from rover.sim.part_travel import BUTTON_TARGET, DRAWER_OPEN_Q, DRAWER_START_OPEN
from rover.sim.tasks._common import (
    door_opening_levels,
    joint_subtask,
    named_levels,
    part_spec,
    touch_subtask,
)
from rover.sim.tasks.articulated import drawer_protocol
from rover.sim.tasks.base import GoalSpec, QATemplate, TaskSpec

SUITE = "kitchen"
QUARTER = float(np.pi / 2)
DOOR_OPEN = 1.2  # rad a cabinet door swings to count as open
SPOUT_TURN = 0.8  # rad the sink spout swivels


def _qa(obj: str, items: list[tuple[str, str, str]]) -> list[QATemplate]:
    return [QATemplate(id=i, text=t, event=e, object=obj) for i, t, e in items]


def _spec(name: str, **fields) -> TaskSpec:
    return TaskSpec(
        name=f"{SUITE}.{name}",
        env_name="RoverKitchen",
        suite=SUITE,
        paraphrases=PARAPHRASES.get(name, []),
        **fields,
    )


# --------------------------------------------------------------- doors/drawers
def _drawer(closing: bool) -> TaskSpec:
    kwargs = {"fixture": "Drawer", "part": "drawer"}
    if closing:  # closed = at most 10% open: 93% of the way from 14 cm
        kwargs.update(start_q=DRAWER_START_OPEN, target=0.0, reach=0.93)
    else:
        kwargs.update(target=DRAWER_OPEN_Q)
    return _spec(
        "CloseDrawer" if closing else "OpenDrawer",
        env_kwargs=kwargs,
        group="doors_drawers",
        objects=[part_spec("drawer", "Drawer", "drawer", "centre", handle="handle")],
        **drawer_protocol(closing),
    )


OPEN_SINGLE_DOOR = _spec(
    "OpenSingleDoor",
    env_kwargs={"fixture": "Cabinet", "part": "door", "target": DOOR_OPEN},
    description="Grasp the cabinet door's handle and swing the door open.",
    group="doors_drawers",
    objects=[part_spec("door", "Cabinet", "door", "centre", handle="handle")],
    goals={"door_swung": GoalSpec(kind="fixture", object="door", body="handle")},
    subtasks=[
        touch_subtask("grasp the door handle", "door", "door:handle", "grasped:door"),
        joint_subtask(
            "swing the door open", "door", "door:handle", "goal:door_swung", "turned:door"
        ),
    ],
    levels=door_opening_levels(),
    milestones=["approach:door", "contact:door", "open_start:door", "open_finish:door"],
    qa_templates=_qa(
        "door",
        [
            ("did_contact", "Did the robot contact the door handle? If so, when?", "contact"),
            ("did_grasp", "Did the robot grasp the door handle? If so, when?", "grasp"),
            ("did_open_start", "Did the robot start opening the door? If so, when?", "open_start"),
            (
                "did_open_finish",
                "Did the robot completely open the door? If so, when?",
                "open_finish",
            ),
        ],
    ),
    expert="kitchen_swing",
    max_expert_steps=320,
)


def _close_single_door() -> TaskSpec:
    """The cabinet door starts swung open `DOOR_OPEN` and is pushed shut: the drawer
    protocol with "door" (facts: the door's opening fraction; events close_start,
    close_finish), carried along its arc by the swing expert."""
    proto = drawer_protocol(closing=True, part="door")
    proto.update(
        description="Grasp the cabinet door's handle and swing the door closed.",
        expert="kitchen_swing",
        max_expert_steps=320,
    )
    return _spec(
        "CloseSingleDoor",
        # closed = at most 10% open (7 degrees): 92% of the way from DOOR_OPEN
        env_kwargs={
            "fixture": "Cabinet",
            "part": "door",
            "start_q": DOOR_OPEN,
            "target": 0.0,
            "reach": 0.92,
        },
        group="doors_drawers",
        objects=[part_spec("door", "Cabinet", "door", "centre", handle="handle")],
        **proto,
    )


# ----------------------------------------------------------- appliances on/off
def _button(name: str, fixture: str, appliance: str) -> TaskSpec:
    return _spec(
        name,
        env_kwargs={"fixture": fixture, "part": "button", "target": BUTTON_TARGET},
        description=f"Press the start button of the {appliance} to turn it on.",
        group="appliances",
        objects=[part_spec("button", fixture, "button", "top", top="top")],
        goals={"button_pressed": GoalSpec(kind="fixture", object="button", body="top")},
        subtasks=[
            touch_subtask(
                f"reach the {appliance}'s start button", "button", "button:top", "touched:button"
            ),
            joint_subtask(
                "press the button down",
                "button",
                "button:top",
                "goal:button_pressed",
                "pressed:button",
            ),
        ],
        levels=named_levels(
            [[], []],
            [
                "Fail to approach the on/off button",
                "Approach the on/off button",
                f"Press the button and turn the {appliance} on",
            ],
        ),
        milestones=["approach:button", "press:button"],
        qa_templates=_qa(
            "button",
            [
                (
                    "did_press",
                    f"Did the robot press the start button of the {appliance}? If so, when?",
                    "press",
                ),
                ("did_turn_on", f"Did the robot turn the {appliance} on? If so, when?", "turn_on"),
            ],
        ),
        expert="button",
        max_expert_steps=200,
    )


TURN_OFF_MICROWAVE = _spec(
    "TurnOffMicrowave",
    # the microwave runs at the start; its red stop button latches down when pressed
    env_kwargs={
        "fixture": "Microwave",
        "part": "stop",
        "facts_as": "stop button",
        "target": BUTTON_TARGET,
    },
    description="Press the stop button of the microwave to turn it off.",
    group="appliances",
    objects=[part_spec("stop button", "Microwave", "stop", "stop_top", top="stop_top")],
    goals={"button_pressed": GoalSpec(kind="fixture", object="stop button", body="stop_top")},
    subtasks=[
        touch_subtask(
            "reach the microwave's stop button",
            "stop button",
            "stop button:top",
            "touched:stop button",
        ),
        joint_subtask(
            "press the stop button down",
            "stop button",
            "stop button:top",
            "goal:button_pressed",
            "pressed:stop button",
        ),
    ],
    levels=named_levels(
        [[], []],
        [
            "Fail to approach the on/off button",
            "Approach the on/off button",
            "Press the button and turn the microwave off",
        ],
    ),
    milestones=["approach:stop button", "press:stop button"],
    qa_templates=_qa(
        "stop button",
        [
            (
                "did_press",
                "Did the robot press the stop button of the microwave? If so, when?",
                "press",
            ),
            ("did_turn_off", "Did the robot turn the microwave off? If so, when?", "turn_off"),
        ],
    ),
    expert="button",
    max_expert_steps=200,
)


# ---------------------------------------------------------- fixtures and knobs
def _early_start(milestones: list[list[str]], names: list[str]) -> list:
    """Table-5 levels whose "start turning" video stops early in the turn (20-35% of its
    expert steps, not around half): a dial turns fast, and random wrist motions from a
    closed grip at half way often finish the turn, showing the next level."""
    levels = named_levels(milestones, names)
    return [
        lv.model_copy(update={"terminate_at": (0.2, 0.35)}) if lv.level == 4 else lv
        for lv in levels
    ]


def _dial(
    name: str,
    fixture: str,
    part_words: str,
    thing: str,
    on: bool,
    tip: str = "tip",
    kind: str = "knob",
    turn: float = QUARTER,
    obj: str = "knob",
) -> TaskSpec:
    """A part turned about a vertical axis: stove knob, faucet handle, sink spout.

    `obj` is what the task object, its facts and events call the part ("sink handle"),
    `kind` the fixture's joint ("knob": the faucet lever is the sink's dial)."""
    kwargs: dict = {"fixture": fixture, "part": kind, "target": turn if on else 0.0}
    if not on:
        kwargs["start_q"] = turn
    if obj != kind:
        kwargs["facts_as"] = obj
    body = "knob" if kind == "knob" else kind
    centre = "centre" if kind == "knob" else tip
    state = "on" if on else "off"
    what = f"turn {state} the {thing}" if kind == "knob" else f"turn the {thing}"
    return _spec(
        name,
        env_kwargs=kwargs,
        description=f"Grasp the {part_words} and {what}.",
        group="fixtures_knobs",
        objects=[part_spec(obj, fixture, body, centre, tip=tip)],
        goals={"knob_turned": GoalSpec(kind="fixture", object=obj, body=tip)},
        subtasks=[
            touch_subtask(f"grasp the {part_words}", obj, obj, f"grasped:{obj}"),
            joint_subtask(
                f"turn the {part_words}", obj, f"{obj}:tip", "goal:knob_turned", f"turned:{obj}"
            ),
        ],
        levels=_early_start(
            [[f"Approach the {part_words}"], [f"Start turning the {part_words}"]],
            [
                f"Fail to approach the {part_words}",
                f"Approach the {part_words}",
                f"Contact the {part_words}",
                f"Start turning the {part_words}",
                f"Finish turning the {part_words}",
            ],
        ),
        milestones=[f"approach:{obj}", f"contact:{obj}", f"turn_start:{obj}", f"turn_finish:{obj}"],
        qa_templates=_qa(
            obj,
            [
                ("did_contact", f"Did the robot contact the {part_words}? If so, when?", "contact"),
                (
                    "did_turn_start",
                    f"Did the robot start turning the {part_words}? If so, when?",
                    "turn_start",
                ),
                (
                    "did_turn_finish",
                    f"Did the robot completely {what}? If so, when?",
                    "turn_finish",
                ),
            ],
        ),
        expert="kitchen_turn" if kind == "knob" else "kitchen_swing",
        max_expert_steps=280,
    )


TASKS: list[TaskSpec] = [
    _drawer(closing=False),
    _drawer(closing=True),
    OPEN_SINGLE_DOOR,
    _close_single_door(),
    _button("TurnOnMicrowave", "Microwave", "microwave"),
    TURN_OFF_MICROWAVE,
    _button("CoffeePressButton", "Coffee", "coffee machine"),
    _dial("TurnOnStove", "Stove", "stove knob", "stove", on=True),
    _dial("TurnOffStove", "Stove", "stove knob", "stove", on=False),
    _dial(
        "TurnOnSinkFaucet",
        "Sink",
        "sink handle",
        "sink",
        on=True,
        tip="handle_tip",
        obj="sink handle",
    ),
    _dial(
        "TurnOffSinkFaucet",
        "Sink",
        "sink handle",
        "sink",
        on=False,
        tip="handle_tip",
        obj="sink handle",
    ),
    _dial(
        "TurnSinkSpout",
        "Sink",
        "sink spout",
        "sink spout",
        on=True,
        kind="spout",
        turn=SPOUT_TURN,
        obj="sink spout",
    ),
]
# levels leave the expert by milestone, as the tabletop tasks' do (each level between
# its demo's achievement of component L-1 and L, with the ending component L's kind gets)
TASKS = [t.model_copy(update={"levels": by_milestone(t.levels, t.milestones)}) for t in TASKS]
TASKS += PICK_PLACE_TASKS  # the pick-and-place group (rover.sim.kitchen.pick_place)
TASKS += COMPOSITE_TASKS  # the composite groups (rover.sim.kitchen.composites)
TASKS += FORWARD_COMPOSITE_TASKS  # composites into openings (kitchen.forward_composites)
TASKS += [microwave_thawing()]  # two parts of one fixture (rover.sim.kitchen.thawing)
