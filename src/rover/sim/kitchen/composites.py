"""The kitchen suite's composite tasks (paper App. B, Tables 4 and 5; App. C.3; App. N).

A composite task chains several atomic ones in one 60-frame video. Its object-centric
subtasks (App. N) are those of the atomic tasks it chains, in order (pick up the first
vegetable, place it on the board, pick up the second, place it), and its levels are
Table 5's row for its group: each level is one *component* of the task (e.g. "pick up
the first vegetable and place it on the cutting board"), and a video of level L shows
every earlier component achieved and component L not (`TaskSpec.milestones`, checked
on the video's facts by `rover.sim.milestones`). The scene is `RoverKitchenComposite`
(`rover.sim.kitchen.composite_env`): the kitchen with one free body per item.

Built here: ArrangeVegetables. Items are named by their role ("the first vegetable"),
which stays fixed per task while the drawn instances (a tomato, a carrot, ...) change
with the seed and are recorded in ``episode.json``.
"""

from __future__ import annotations

from rover.sim.kitchen.language import PARAPHRASES
from rover.sim.kitchen.utensils import BOARD_REGION, ItemRole, item_body
from rover.sim.levels import ENDINGS_BY_KIND, LevelSpec, by_milestone, default_levels
from rover.sim.tasks._common import grasp_subtask, move_subtask, pick_place_qa
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

SUITE = "kitchen"
# level 1 "fail to pick up the first item": leave the expert early on its way to the
# item, fingers open, so it is never lifted (the component the level fails is the whole
# pick-and-place, whose own ending would keep carrying it)
FAIL_TO_PICK = {
    **ENDINGS_BY_KIND["pick_up"],
    "milestone_cut": (0.0, 0.3),
    "terminal_w": (20, 40),
}


def _pick_and_place(role: ItemRole, where: str, goal: str) -> list[SubtaskSpec]:
    return [
        grasp_subtask(f"pick up the {role.name}", role.name),
        move_subtask(f"place the {role.name} {where}", role.name, goal, f"placed:{role.name}"),
    ]


def component_levels(names: list[str], subtasks_per_component: list[int]) -> list[LevelSpec]:
    """Table 5's composite levels: level 1 fails the first component, level L stops right
    after component L-1 (at the start of the next component's first subtask), the top
    level completes the task near-expert. The subtask-fraction knobs are the fallback;
    `by_milestone` then cuts each level between its demo's components."""
    per_subtask = default_levels([[] for _ in range(sum(subtasks_per_component))])
    chosen = [per_subtask[0]]
    first = 0
    for n in subtasks_per_component[:-1]:
        first += n
        chosen.append(per_subtask[first])  # "stop right at the start of subtask `first`"
    chosen.append(per_subtask[-1])
    if len(chosen) != len(names):
        raise ValueError(f"{len(names)} level names for {len(chosen)} levels")
    return [
        lv.model_copy(update={"level": k + 1, "name": n})
        for k, (lv, n) in enumerate(zip(chosen, names, strict=True))
    ]


def _spec(name: str, **fields) -> TaskSpec:
    return TaskSpec(
        name=f"{SUITE}.{name}",
        env_name="RoverKitchenComposite",
        suite=SUITE,
        paraphrases=PARAPHRASES.get(name, []),
        frames=60,
        **fields,
    )


def arrange_vegetables() -> TaskSpec:
    """Two vegetables (two different instances) from the counter onto a cutting board."""
    on_board = "on the cutting board"
    roles = [
        # the near one first: the hand on its way to the far one would sweep over it
        ItemRole("first vegetable", "vegetable", "counter near", BOARD_REGION.name),
        ItemRole("second vegetable", "vegetable", "counter far", BOARD_REGION.name),
    ]
    spots = ["board_spot_1", "board_spot_2"]
    subtasks: list[SubtaskSpec] = []
    qa: list[QATemplate] = []
    goals: dict[str, GoalSpec] = {}
    for k, (role, spot) in enumerate(zip(roles, spots, strict=True), start=1):
        goals[f"board_{k}"] = GoalSpec(kind="body", body=spot)
        subtasks += _pick_and_place(role, on_board, f"goal:board_{k}")
        qa += [q for q in pick_place_qa(role.name, on_board) if q.id != "did_contact"]
    milestones = [f"place:{r.name}" for r in roles]
    levels = component_levels(
        [
            "Fail to pick up the first vegetable",
            "Pick up the first vegetable and place it on the cutting board",
            "Pick up the second vegetable and place it on the cutting board",
        ],
        [2, 2],
    )
    levels = by_milestone(levels, milestones)
    levels[0] = levels[0].model_copy(update=FAIL_TO_PICK)
    return _spec(
        "ArrangeVegetables",
        env_kwargs={
            "fixture": "Cabinet",
            "part": "door",
            "items": [[r.name, r.category, r.start, r.goal] for r in roles],
            "board": True,
        },
        description=(
            "Pick up the two vegetables from the counter and place them on the cutting board."
        ),
        group="arrange_vegetables",
        objects=[ObjectSpec(name=r.name, body=item_body(r)) for r in roles],
        goals=goals,
        subtasks=subtasks,
        levels=levels,
        milestones=milestones,
        qa_templates=qa,
        expert="kitchen_chain",  # picks and places each item in turn, home between
        max_expert_steps=900,
    )


TASKS: list[TaskSpec] = [arrange_vegetables()]
