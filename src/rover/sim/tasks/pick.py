"""Pick group: robosuite Lift (grasp the cube and lift it)."""

from __future__ import annotations

from rover.sim.levels import by_milestone
from rover.sim.tasks._common import (
    PICK_PLACE_ENDINGS,
    grasp_subtask,
    move_subtask,
    named_levels,
)
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, TaskSpec

MILESTONES = ["approach:cube", "contact:cube", "pick_up:cube"]

LIFT = TaskSpec(
    name="Lift",
    env_name="Lift",
    description="Pick up the red cube from the table and lift it.",
    group="pick",
    objects=[ObjectSpec(name="cube", body="cube_main")],
    goals={"lift": GoalSpec(kind="start_offset", object="cube", offset=(0.0, 0.0, 0.15))},
    subtasks=[
        grasp_subtask("grasp the cube", "cube", signal="grasped:cube"),
        move_subtask("lift the cube", "cube", "goal:lift", "lifted:cube", beta=0.7),
    ],
    levels=by_milestone(
        named_levels(
            [["Approach the cube"], []],
            [
                "Fail to approach the cube",
                "Approach the cube",
                "Contact the cube",
                "Pick up the cube",
            ],
        ),
        MILESTONES,
        PICK_PLACE_ENDINGS,
    ),
    milestones=MILESTONES,
    qa_templates=[
        QATemplate(
            id="did_contact",
            text="Did the robot contact the cube? If so, when?",
            event="contact",
            object="cube",
        ),
        QATemplate(
            id="did_grasp",
            text="Did the robot grasp the cube? If so, when?",
            event="grasp",
            object="cube",
        ),
        QATemplate(
            id="did_pick_up",
            text="Did the robot pick up the cube? If so, when?",
            event="pick_up",
            object="cube",
        ),
        QATemplate(
            id="did_drop",
            text="Did the robot drop the cube? If so, when?",
            event="drop",
            object="cube",
        ),
    ],
    expert="lift",
    max_expert_steps=250,
)

TASKS = [LIFT]
