"""Stacking group: robosuite Stack (red cube onto green cube)."""

from __future__ import annotations

from rover.sim.tasks._common import (
    grasp_subtask,
    move_subtask,
    pick_place_levels,
    pick_place_milestones,
    pick_place_qa,
)
from rover.sim.tasks.base import GoalSpec, ObjectSpec, TaskSpec

TARGET = "on the green cube"

STACK = TaskSpec(
    name="Stack",
    env_name="Stack",
    description="Pick up the red cube and stack it on the green cube.",
    group="stacking",
    objects=[
        ObjectSpec(name="red cube", body="cubeA_main"),
        ObjectSpec(name="green cube", body="cubeB_main"),
    ],
    goals={"on": GoalSpec(kind="above", object="green cube", offset=(0.0, 0.0, 0.045))},
    subtasks=[
        grasp_subtask("pick up the red cube", "red cube"),
        move_subtask(f"place the red cube {TARGET}", "red cube", "goal:on", "stacked:red cube"),
    ],
    levels=pick_place_levels("red cube", TARGET),
    milestones=pick_place_milestones("red cube"),
    qa_templates=pick_place_qa("red cube", TARGET),
    expert="stack",
    max_expert_steps=400,
)

TASKS = [STACK]
