"""Drawers, buttons and knobs groups (App. B): rover's own articulated fixtures.

RoboCasa's OpenDrawer/CloseDrawer, TurnOnMicrowave/CoffeePressButton and
TurnSinkSpout/TurnOnStove tasks need kitchen assets that cannot be downloaded here, so
these tasks use small MJCF fixtures on robosuite's table (`rover.sim.fixtures`): a
cabinet drawer, an appliance with a push button and a dial knob. Levels follow Table 5's
rows for each group and QA templates follow App. C.3.
"""

from __future__ import annotations

from typing import Any

from rover.sim.levels import by_milestone
from rover.sim.part_travel import DRAWER_START_OPEN
from rover.sim.tasks._common import FINGERS, joint_subtask, named_levels
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

_DRAWER = ObjectSpec(
    name="drawer",
    body="Drawer_drawer",
    centre="Drawer_centre",
    sites={"handle": "Drawer_handle"},
    graspable=False,
)


def _qa(items: list[tuple[str, str, str]], obj: str) -> list[QATemplate]:
    return [QATemplate(id=i, text=t, event=e, object=obj) for i, t, e in items]


def drawer_protocol(closing: bool, part: str = "drawer") -> dict[str, Any]:
    """A drawer task wherever the drawer stands: its sentence, goal, subtasks, Table 5
    levels and milestones, App. C.3 questions and expert. The tabletop and kitchen suites
    differ only in the environment around the drawer, so both build from this. `part`
    "door" gives a hinged door's (the kitchen's CloseSingleDoor): the same sentence,
    subtasks, levels and questions with "door", end signals ``door_closed`` /
    ``door_opened``; the caller sets the door's expert."""
    verb, signal = ("close", f"{part}_closed") if closing else ("open", f"{part}_opened")
    ing = "closing" if closing else "opening"
    push, end = ("push", "closed") if closing else ("pull", "open")
    return {
        "description": f"Grasp the {part} handle and {push} the {part} {end}.",
        "goals": {f"{part}_{verb}": GoalSpec(kind="fixture", object=part, body="handle")},
        "subtasks": [
            SubtaskSpec(
                name=f"grasp the {part} handle",
                object=part,
                robot_points=FINGERS,
                object_points=[f"{part}:handle", f"{part}:handle"],
                end_signal=f"grasped:{part}",
            ),
            joint_subtask(
                f"{push} the {part} {end}",
                part,
                f"{part}:handle",
                f"goal:{part}_{verb}",
                f"{signal}:{part}",
            ),
        ],
        "levels": named_levels(
            [[f"Approach the {part}"], [f"Start {ing} the {part}"]],
            [
                f"Fail to approach the {part}",
                f"Approach the {part}",
                f"Contact the {part}",
                f"Start {ing} the {part}",
                f"Finish {ing} the {part}",
            ],
        ),
        "milestones": [
            f"approach:{part}",
            f"contact:{part}",
            f"{verb}_start:{part}",
            f"{verb}_finish:{part}",
        ],
        "qa_templates": _qa(
            [
                (
                    "did_contact",
                    f"Did the robot contact the {part} handle? If so, when?",
                    "contact",
                ),
                ("did_grasp", f"Did the robot grasp the {part} handle? If so, when?", "grasp"),
                (
                    f"did_{verb}_start",
                    f"Did the robot start {ing} the {part}? If so, when?",
                    f"{verb}_start",
                ),
                (
                    f"did_{verb}_finish",
                    f"Did the robot completely {verb} the {part}? If so, when?",
                    f"{verb}_finish",
                ),
            ],
            part,
        ),
        "expert": "drawer_close" if closing else "drawer_open",
        "max_expert_steps": 300,
    }


def _drawer_task(name: str, closing: bool) -> TaskSpec:
    return TaskSpec(
        name=name,
        env_name="RoverDrawer",
        # closed = at most 10% open (1.2 cm): 93% of the way from 14 cm
        env_kwargs={"start_q": DRAWER_START_OPEN, "target": 0.0, "reach": 0.93} if closing else {},
        group="drawers",
        objects=[_DRAWER],
        **drawer_protocol(closing),
    )


OPEN_DRAWER = _drawer_task("OpenDrawer", closing=False)
CLOSE_DRAWER = _drawer_task("CloseDrawer", closing=True)

PRESS_BUTTON = TaskSpec(
    name="PressButton",
    env_name="RoverButton",
    description="Press the button to turn the appliance on.",
    group="buttons",
    objects=[
        ObjectSpec(
            name="button",
            body="Button_button",
            centre="Button_top",
            sites={"top": "Button_top"},
            graspable=False,
        )
    ],
    goals={"button_pressed": GoalSpec(kind="fixture", object="button", body="top")},
    subtasks=[
        SubtaskSpec(
            name="reach the button",
            object="button",
            robot_points=FINGERS,
            object_points=["button:top", "button:top"],
            end_signal="touched:button",
        ),
        SubtaskSpec(
            name="press the button down",
            object="button",
            robot_points=FINGERS,
            object_points=["button:top", "button:top"],
            goal="goal:button_pressed",
            joint="joint:button",
            beta=0.8,
            end_signal="pressed:button",
        ),
    ],
    levels=named_levels(
        [[], []],
        [
            "Fail to approach the on/off button",
            "Approach the on/off button",
            "Press the button and turn the appliance on",
        ],
    ),
    milestones=["approach:button", "press:button"],
    qa_templates=_qa(
        [
            ("did_contact", "Did the robot contact the button? If so, when?", "contact"),
            ("did_press", "Did the robot press the button? If so, when?", "press"),
            ("did_turn_on", "Did the robot turn the appliance on? If so, when?", "turn_on"),
        ],
        "button",
    ),
    expert="button",
    max_expert_steps=200,
)

TURN_KNOB = TaskSpec(
    name="TurnKnob",
    env_name="RoverKnob",
    description="Grasp the knob and turn it a quarter turn counter-clockwise.",
    group="knobs",
    objects=[
        ObjectSpec(
            name="knob",
            body="Knob_knob",
            centre="Knob_centre",
            sites={"tip": "Knob_tip"},
            graspable=False,
        )
    ],
    goals={"knob_turned": GoalSpec(kind="fixture", object="knob", body="tip")},
    subtasks=[
        SubtaskSpec(
            name="grasp the knob",
            object="knob",
            robot_points=FINGERS,
            object_points=["knob", "knob"],
            end_signal="grasped:knob",
        ),
        SubtaskSpec(
            name="turn the knob",
            object="knob",
            robot_points=FINGERS,
            object_points=["knob:tip", "knob:tip"],
            goal="goal:knob_turned",
            joint="joint:knob",
            beta=0.8,
            end_signal="turned:knob",
        ),
    ],
    levels=named_levels(
        [["Approach the knob"], ["Start turning the knob"]],
        [
            "Fail to approach the knob",
            "Approach the knob",
            "Contact the knob",
            "Start turning the knob",
            "Finish turning the knob",
        ],
    ),
    milestones=["approach:knob", "contact:knob", "turn_start:knob", "turn_finish:knob"],
    qa_templates=_qa(
        [
            ("did_contact", "Did the robot contact the knob? If so, when?", "contact"),
            ("did_grasp", "Did the robot grasp the knob? If so, when?", "grasp"),
            ("did_turn_start", "Did the robot start turning the knob? If so, when?", "turn_start"),
            (
                "did_turn_finish",
                "Did the robot completely turn the knob? If so, when?",
                "turn_finish",
            ),
        ],
        "knob",
    ),
    expert="knob",
    max_expert_steps=250,
)

# the tabletop tasks' levels leave the expert by milestone (`rover.sim.levels.by_milestone`)
OPEN_DRAWER, PRESS_BUTTON, TURN_KNOB, CLOSE_DRAWER = (
    t.model_copy(update={"levels": by_milestone(t.levels, t.milestones)})
    for t in (OPEN_DRAWER, PRESS_BUTTON, TURN_KNOB, CLOSE_DRAWER)
)

# every articulated task; the registry takes those whose expert passed the 90% bar
ALL_TASKS = [OPEN_DRAWER, PRESS_BUTTON, TURN_KNOB, CLOSE_DRAWER]
TASKS = ALL_TASKS
