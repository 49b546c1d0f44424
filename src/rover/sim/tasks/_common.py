"""Building blocks shared by the task spec files: fingers, levels, QA wordings."""

from __future__ import annotations

from collections.abc import Sequence

from rover.sim.levels import LevelSpec, by_milestone, default_levels
from rover.sim.tasks.base import ObjectSpec, QATemplate, SubtaskSpec

FINGERS = ["left_finger", "right_finger"]


def grasp_subtask(name: str, obj: str, point: str | None = None, signal: str = "") -> SubtaskSpec:
    """Bring both fingers to the object (no goal term): "pick up the can"."""
    return move_subtask(name, obj, None, signal or f"lifted:{obj}", beta=0.0, point=point)


def move_subtask(
    name: str, obj: str, goal: str | None, signal: str, beta: float = 0.8, point: str | None = None
) -> SubtaskSpec:
    """Carry the object to a goal point, mostly measured by the object-goal distance."""
    where = point or obj
    return SubtaskSpec(
        name=name,
        object=obj,
        robot_points=FINGERS,
        object_points=[where, where],
        goal=goal,
        beta=beta,
        end_signal=signal,
    )


def part_spec(name: str, fixture: str, body: str, centre: str, **sites: str) -> ObjectSpec:
    """The task object of a fixture part (not graspable), its bodies and sites named by the
    fixture's MuJoCo prefix: ``part_spec("button", "Coffee", "button", "top", top="top")``."""
    return ObjectSpec(
        name=name,
        body=f"{fixture}_{body}",
        centre=f"{fixture}_{centre}",
        sites={k: f"{fixture}_{v}" for k, v in sites.items()},
        graspable=False,
    )


def touch_subtask(name: str, obj: str, point: str, signal: str) -> SubtaskSpec:
    """Bring both fingers to a fixture part's `point` (no goal term): "grasp the door
    handle", "reach the start button"."""
    return SubtaskSpec(
        name=name, object=obj, robot_points=FINGERS, object_points=[point, point], end_signal=signal
    )


def joint_subtask(
    name: str, obj: str, point: str, goal: str, signal: str, key: str | None = None
) -> SubtaskSpec:
    """Move a fixture part to its target by `point` (a handle, a lever's tip, a button's
    top): the goal term follows the joint ``joint:<key>`` (the part's own, or worked
    entry `key` of an env that works several parts) toward the target."""
    return SubtaskSpec(
        name=name,
        object=obj,
        robot_points=FINGERS,
        object_points=[point, point],
        goal=goal,
        joint=f"joint:{key or obj}",
        beta=0.8,
        end_signal=signal,
    )


def named_levels(milestones: Sequence[Sequence[str]], names: Sequence[str]) -> list[LevelSpec]:
    """B's default Table-5 levels, relabelled with this task's wording."""
    levels = default_levels(milestones)
    if len(names) != len(levels):
        raise ValueError(f"{len(names)} level names for {len(levels)} levels")
    return [lv.model_copy(update={"name": n}) for lv, n in zip(levels, names, strict=True)]


def door_opening_levels() -> list[LevelSpec]:
    """Table 5's doors group for opening a hinged door (tabletop Door, kitchen
    OpenSingleDoor): five levels, from failing to approach to finishing the swing."""
    return named_levels(
        [["Approach the door"], ["Start opening the door"]],
        [
            "Fail to approach the door",
            "Approach the door",
            "Contact the door",
            "Start opening the door",
            "Finish opening the door",
        ],
    )


def contact_before_grasp(levels: list[LevelSpec], level: int = 3) -> list[LevelSpec]:
    """An articulated task's "contact" level stops near the end of the grasp subtask
    (fingers at the handle, not yet closed on it) instead of just after the grasp: random
    actions from a closed grasp pull the part open, so that ending would show the next
    level ("start opening")."""
    return [
        lv.model_copy(update={"terminate_subtask": 0, "terminate_at": (0.8, 0.95)})
        if lv.level == level
        else lv
        for lv in levels
    ]


# How a pick-and-place level ends before its next component (replacing those kinds of
# `rover.sim.levels.ENDINGS_BY_KIND`; see docs/generate.md, "Pick-and-place levels"). The
# value of the pick-up subtask changes by a few hundredths between the approach, the
# contact and the grasp (it is normalised over the whole reach), so each ending leaves
# a state whose value sits where its level belongs, by construction rather than by luck:
# approached, not touched: leave early in the stretch, the open hand backing off upwards
# (random motion beside a small cube or in a sink basin touched the object)
# touched, not held: leave before the fingers close, lift the open hand a few cm off the
# object (never dragging or knocking it), so it ends below the contact
# picked up, not carried: open at the lift while lowering the hand, so the object is set
# back down between the fingers and the hand stays at it: the pick-up undone with the
# hand where it grasped, valued as the grasp (above the contact, which the hand left)
PICK_PLACE_ENDINGS: dict[str, dict] = {
    "contact": {
        "milestone_cut": (0.0, 0.3),
        "terminal_grip": "open",
        "terminal_w": (8, 14),
        "scale": (0.05, 0.15),
        "terminal_drift": (0.0, 0.0, 0.3),
    },
    "pick_up": {
        "milestone_cut": (0.0, 0.4),
        "terminal_grip": "open",
        "terminal_w": (10, 16),
        "scale": (0.0, 0.1),
        "terminal_drift": (0.0, 0.0, 0.3),
    },
    "carry": {
        "milestone_cut": (0.0, 0.2),
        "terminal_grip": "open",
        "terminal_settle": (10, 16),
        "terminal_w": (8, 12),
        "scale": (0.0, 0.05),
        "terminal_drift": (0.0, 0.0, -0.4),
    },
}


def pick_place_levels(obj: str, target: str) -> list[LevelSpec]:
    """App. B Table 5, pick-and-place group: seven levels, cut by milestone."""
    levels = named_levels(
        [
            [f"Approach the {obj}", f"Contact the {obj}"],
            [f"Keep grasp of the {obj}", f"Approach placing the {obj} {target}"],
        ],
        [
            f"Fail to approach the {obj}",
            f"Approach the {obj}",
            f"Contact the {obj}",
            f"Pick up the {obj}",
            f"Keep grasp of the {obj}",
            f"Approach placing the {obj} {target}",
            f"Place the {obj} {target}",
        ],
    )
    return by_milestone(levels, pick_place_milestones(obj), PICK_PLACE_ENDINGS)


def pick_place_protocol(
    obj: str,
    target: str,
    goal: str,
    signal: str | None = None,
    point: str | None = None,
    expert: str = "pick_place",
) -> dict:
    """The spec fields every pick-and-place task shares (tabletop bins and pegs, kitchen
    regions): the two object-centric subtasks, Table 5's seven levels and milestones, the
    App. C.3 questions and the expert. ``goal`` names the task's goal ("goal:bin"),
    ``signal`` its end test (default ``placed:<obj>``), ``point`` where the object is taken."""
    return {
        "group": "pick_and_place",
        "subtasks": [
            grasp_subtask(f"pick up the {obj}", obj, point=point),
            move_subtask(f"place the {obj} {target}", obj, goal, signal or f"placed:{obj}"),
        ],
        "levels": pick_place_levels(obj, target),
        "milestones": pick_place_milestones(obj),
        "qa_templates": pick_place_qa(obj, target),
        "expert": expert,
        "max_expert_steps": 500,
    }


def pick_place_milestones(obj: str) -> list[str]:
    """The six components separating the seven pick-and-place levels."""
    return [
        f"{k}:{obj}" for k in ("approach", "contact", "pick_up", "carry", "approach_goal", "place")
    ]


def pick_place_qa(obj: str, target: str) -> list[QATemplate]:
    """App. C.3 pick-and-place questions for one object."""
    return [
        QATemplate(
            id="did_contact",
            text=f"Did the robot contact the {obj}? If so, when?",
            event="contact",
            object=obj,
        ),
        QATemplate(
            id="did_pick_up",
            text=f"Did the robot pick up the {obj}? If so, when?",
            event="pick_up",
            object=obj,
        ),
        QATemplate(
            id="did_drop",
            text=f"Did the robot drop the {obj}? If so, when?",
            event="drop",
            object=obj,
        ),
        QATemplate(
            id="did_place",
            text=f"Did the robot place the {obj} {target}? If so, when?",
            event="place",
            object=obj,
            target=target,
        ),
    ]
