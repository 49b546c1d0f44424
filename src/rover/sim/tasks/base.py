"""Declarative task specifications for the benchmark generator.

A `TaskSpec` says everything the generator needs to know about one task without any
simulator code: which robosuite environment to build and how, what the task is called
in natural language, which objects matter (with human-readable names), the
object-centric subtask sequence the ground-truth value is built from (paper Sec. 4,
App. N), the non-expert levels (App. B, Table 5) and the video-QA templates (App. C.3).
The robosuite wrapper (`rover.sim.env`) resolves the named points and predicates a spec
mentions; the trajectory and value code (`rover.sim.perturb`, `rover.sim.value`) reads
only the fields documented in the simulation contract.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, Field

from rover.sim.levels import LevelSpec

TaskGroup = Literal[
    "pick",
    "pick_and_place",
    "stacking",
    "doors",
    "composite",
    "drawers",
    "buttons",
    "knobs",
    # the kitchen suite's groups (paper App. B, Table 4)
    "doors_drawers",
    "appliances",
    "fixtures_knobs",
    "microwave_thawing",
    "restock_pantry",
    "arrange_vegetables",
    "prepare_coffee",
    "presoak_pan",
]


class ObjectSpec(BaseModel):
    """One task object: its human-readable name and where it lives in the MuJoCo model."""

    name: str  # "can", "red cube", "door"
    body: str  # MuJoCo body whose subtree holds the object's geoms, e.g. "Can_main"
    centre: str | None = None  # site or body giving the object's centre (default: body)
    sites: dict[str, str] = Field(default_factory=dict)  # contact points: "handle" -> site
    graspable: bool = True  # free object that can be lifted (False: door, peg)


class GoalSpec(BaseModel):
    """A named goal point ``goal:<name>``, resolved by the env wrapper in each state.

    Kinds:
        ``bin``: the PickPlace target compartment of ``object`` (robosuite's placement).
        ``above``: the point ``offset`` above the centre of ``object`` (stack on a cube).
        ``body``: a model body (a peg) plus ``offset``.
        ``start_offset``: where ``object`` started the episode, plus ``offset`` (lift).
        ``door_open``: the ``object`` handle site rotated about the door hinge to
        ``angle`` radians (door opened).
        ``fixture``: fixture site ``body`` with the fixture's joint at its target
        (drawer pulled out, button pressed, knob turned; `rover.sim.articulation`).
    """

    kind: Literal["bin", "above", "body", "start_offset", "door_open", "fixture"]
    object: str | None = None
    body: str | None = None
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angle: float = 0.0


class SubtaskSpec(BaseModel):
    """One object-centric subtask (MimicGen style): manipulation relative to one object."""

    name: str  # natural language, e.g. "grasp the can"
    object: str  # reference object (an ObjectSpec name)
    robot_points: list[str]  # e.g. ["left_finger", "right_finger"]
    object_points: list[str]  # same length, e.g. ["can", "can"]
    goal: str | None = None  # named point for y^{e,f}, e.g. "goal:bin"; None: no goal term
    beta: float = 0.0  # weight of the goal term in [0, 1]
    end_signal: str  # predicate the env evaluates, e.g. "lifted:can", "placed:can"
    # articulated goal: point "joint:<object>" (fraction of the joint's way to its goal);
    # progress measures the goal term by it rather than by the goal point's distance
    joint: str | None = None


class QATemplate(BaseModel):
    """A video-QA question template (App. C.3) tied to the event that answers it."""

    id: str  # "did_pick_up"
    text: str  # "Did the robot pick up the {obj}? If so, when?"
    event: str  # event name answering it: contact, grasp, pick_up, drop, place, ...
    object: str  # object the event concerns
    target: str | None = None  # target location wording for {target}


class TaskSpec(BaseModel):
    """Everything declarative about one benchmark task."""

    name: str  # registry name, e.g. "PickPlaceCan"
    env_name: str  # robosuite environment
    env_kwargs: dict[str, Any] = Field(default_factory=dict)
    description: str  # the instruction given to reasoning methods
    group: TaskGroup
    objects: list[ObjectSpec]
    goals: dict[str, GoalSpec] = Field(default_factory=dict)
    subtasks: list[SubtaskSpec]
    levels: list[LevelSpec]
    # Table 5 components in order ("approach:can", "pick_up:can", ...): level L shows the
    # first L-1 and not the L-th (`rover.sim.milestones`)
    milestones: list[str] = Field(default_factory=list)
    qa_templates: list[QATemplate] = Field(default_factory=list)
    frames: int = 30  # frames per video: 30 for atomic tasks, 60 for composite ones
    expert: str  # scripted expert name in `rover.sim.experts`
    max_expert_steps: int = 400
    bins: dict[str, int] = Field(default_factory=dict)  # PickPlace: object -> bin index
    clear_objects: list[str] = Field(default_factory=list)  # robosuite objects moved away
    suite: str = "tabletop"  # "tabletop" (robosuite's tasks) or "kitchen" (rover.sim.kitchen)
    # further wordings of `description`; one is picked per episode seed (`instruction`)
    paraphrases: list[str] = Field(default_factory=list)

    def instruction(self, seed: int) -> tuple[int, str]:
        """(index, text) of the wording an episode with this seed is given; 0 = description.

        Subtask names, levels and QA stay fixed: only the instruction shown varies.
        """
        wordings = [self.description, *self.paraphrases]
        k = int(np.random.default_rng([int(seed), 7]).integers(len(wordings)))
        return k, wordings[k]

    def object_spec(self, name: str) -> ObjectSpec:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise KeyError(f"task {self.name} has no object {name!r}")
