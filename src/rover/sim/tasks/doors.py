"""Doors group: robosuite Door (grasp the handle, pull the door open)."""

from __future__ import annotations

from rover.sim.levels import by_milestone
from rover.sim.tasks._common import FINGERS, contact_before_grasp, door_opening_levels
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

MILESTONES = ["approach:door", "contact:door", "open_start:door", "open_finish:door"]
OPEN_ANGLE = 0.35  # rad of hinge travel counted as "completely open" (robosuite: > 0.3)

DOOR = TaskSpec(
    name="Door",
    env_name="Door",
    env_kwargs={"use_latch": False},
    description="Grasp the door handle and pull the door open.",
    group="doors",
    objects=[
        ObjectSpec(name="door", body="Door_door", sites={"handle": "Door_handle"}, graspable=False)
    ],
    goals={"door_open": GoalSpec(kind="door_open", object="door", angle=OPEN_ANGLE)},
    subtasks=[
        SubtaskSpec(
            name="grasp the door handle",
            object="door",
            robot_points=FINGERS,
            object_points=["door:handle", "door:handle"],
            end_signal="grasped:door",
        ),
        SubtaskSpec(
            name="pull the door open",
            object="door",
            robot_points=FINGERS,
            object_points=["door:handle", "door:handle"],
            goal="goal:door_open",
            joint="joint:door",
            beta=0.8,
            end_signal="opened:door",
        ),
    ],
    levels=by_milestone(
        contact_before_grasp(door_opening_levels()),
        MILESTONES,
    ),
    milestones=MILESTONES,
    qa_templates=[
        QATemplate(
            id="did_contact",
            text="Did the robot contact the door handle? If so, when?",
            event="contact",
            object="door",
        ),
        QATemplate(
            id="did_grasp",
            text="Did the robot grasp the door handle? If so, when?",
            event="grasp",
            object="door",
        ),
        QATemplate(
            id="did_open_start",
            text="Did the robot start opening the door? If so, when?",
            event="open_start",
            object="door",
        ),
        QATemplate(
            id="did_open_finish",
            text="Did the robot completely open the door? If so, when?",
            event="open_finish",
            object="door",
        ),
    ],
    expert="door",
    max_expert_steps=400,
)

TASKS = [DOOR]
