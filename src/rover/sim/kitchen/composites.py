"""The kitchen suite's composite tasks (paper App. B, Tables 4 and 5; App. C.3; App. N).

A composite task chains several atomic ones in one 60-frame video. Its object-centric
subtasks (App. N) are those of the atomic tasks it chains, in order (pick up the first
vegetable, place it on the board, pick up the second, place it), and its levels are
Table 5's row for its group: each level is one *component* of the task (e.g. "pick up
the first vegetable and place it on the cutting board"), and a video of level L shows
every earlier component achieved and component L not (`TaskSpec.milestones`, checked
on the video's facts by `rover.sim.milestones`). The scene is `RoverKitchenComposite`
(`rover.sim.kitchen.composite_env`): the kitchen with one free body per item.

Registered here: ArrangeVegetables and PreSoakPan, which ends by working a fixture
part, the sink's faucet handle (the env's ``articulated`` switch makes that part the
scene's joint, with the faucet task's facts, events, goal and expert). Items are named by their
role ("the first vegetable"), which stays fixed per task while the drawn instances (a
tomato, a carrot, ...) change with the seed and are recorded in ``episode.json``.
"""

from __future__ import annotations

from rover.sim.kitchen.language import PARAPHRASES
from rover.sim.kitchen.pan import HANDLE_SITE, INSIDE_SITE, PAN_REGION, site_name
from rover.sim.kitchen.utensils import BOARD_REGION, ItemRole, item_body
from rover.sim.levels import ENDINGS_BY_KIND, LevelSpec, by_milestone, default_levels
from rover.sim.tasks._common import (
    grasp_subtask,
    joint_subtask,
    move_subtask,
    part_spec,
    pick_place_qa,
    touch_subtask,
)
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


def pick_and_place(
    role: ItemRole, where: str, goal: str, point: str | None = None
) -> list[SubtaskSpec]:
    """Pick up an item and place it: `point` is where the hand takes it (a pan by its
    handle; default its centre)."""
    return [
        grasp_subtask(f"pick up the {role.name}", role.name, point=point),
        move_subtask(
            f"place the {role.name} {where}", role.name, goal, f"placed:{role.name}", point=point
        ),
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


def pick_first_levels(
    names: list[str], subtasks_per_component: list[int], milestones: list[str]
) -> list[LevelSpec]:
    """Table 5's levels of a composite whose first component picks an item up: cut by
    milestone between the demo's components, level 1 (fail to pick up the first item)
    leaving the expert early on its way there (`FAIL_TO_PICK`)."""
    levels = by_milestone(component_levels(names, subtasks_per_component), milestones)
    levels[0] = levels[0].model_copy(update=FAIL_TO_PICK)
    return levels


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
        subtasks += pick_and_place(role, on_board, f"goal:board_{k}")
        qa += [q for q in pick_place_qa(role.name, on_board) if q.id != "did_contact"]
    milestones = [f"place:{r.name}" for r in roles]
    levels = pick_first_levels(
        [
            "Fail to pick up the first vegetable",
            "Pick up the first vegetable and place it on the cutting board",
            "Pick up the second vegetable and place it on the cutting board",
        ],
        [2, 2],
        milestones,
    )
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


QUARTER = 1.5707963267948966  # rad: the faucet lever's "on" turn (as TurnOnSinkFaucet)
# the pan's goal point: the basin's site moved toward the front and away from the faucet
# handle's side (world frame), clear of the spout's nozzle above the basin's centre
PAN_IN_SINK = (-0.03, -0.07, 0.0)
SPOUT_ASIDE = 1.0  # rad the sink spout starts swung (toward -y, the basin's back corner)


def _sink_handle() -> tuple[ObjectSpec, GoalSpec, list[SubtaskSpec], list[QATemplate]]:
    """The faucet lever as TurnOnSinkFaucet has it: the part, its goal (the lever's tip
    with the joint at a quarter turn), its two subtasks and App. C.3's two questions."""
    obj = "sink handle"
    part = part_spec(obj, "Sink", "knob", "centre", tip="handle_tip")
    goal = GoalSpec(kind="fixture", object=obj, body="handle_tip")
    subtasks = [
        touch_subtask("grasp the sink handle", obj, obj, f"grasped:{obj}"),
        joint_subtask(
            "turn the sink handle", obj, f"{obj}:tip", "goal:knob_turned", f"turned:{obj}"
        ),
    ]
    qa = [
        QATemplate(
            id="did_contact",
            text="Did the robot contact the sink handle? If so, when?",
            event="contact",
            object=obj,
        ),
        QATemplate(
            id="did_turn_on",
            text="Did the robot turn on the sink? If so, when?",
            event="turn_finish",
            object=obj,
        ),
    ]
    return part, goal, subtasks, qa


def pre_soak_pan() -> TaskSpec:
    """The pan from the counter into the sink, the sponge into the pan, the faucet on."""
    pan = ItemRole("pan", "pan", "counter beside sink", "sink")
    sponge = ItemRole("sponge", "sponge", "counter front", PAN_REGION.name)
    handle, turned, handle_subtasks, handle_qa = _sink_handle()
    pan_sites = {k: site_name(pan.prefix, k) for k in (HANDLE_SITE, INSIDE_SITE)}
    subtasks = [
        *pick_and_place(pan, "in the sink", "goal:sink", point=f"pan:{HANDLE_SITE}"),
        *pick_and_place(sponge, "in the pan", "goal:pan"),
        *handle_subtasks,
    ]
    qa = [q for q in pick_place_qa("pan", "in the sink") if q.id != "did_contact"]
    qa += [q for q in pick_place_qa("sponge", "in the pan") if q.id != "did_contact"]
    qa += handle_qa
    milestones = ["place:pan", "place:sponge", "turn_finish:sink handle"]
    levels = pick_first_levels(
        [  # Table 5 numbers these 1, 2, 2, 4: four levels
            "Fail to pick up the pan",
            "Pick up the pan and place it in the sink",
            "Pick up the sponge and place it in the pan",
            "Turn the sink handle to turn on the sink",
        ],
        [2, 2, 2],
        milestones,
    )
    return _spec(
        "PreSoakPan",
        env_kwargs={
            "fixture": "Sink",
            "part": "knob",
            "facts_as": "sink handle",
            "target": QUARTER,
            "articulated": True,
            # the spout swung toward the pan's far side: over the basin's centre its
            # nozzle stood where the arm's wrist links pass setting the pan and sponge down
            "scenery_q": {"spout": SPOUT_ASIDE},
            "items": [[r.name, r.category, r.start, r.goal] for r in (pan, sponge)],
        },
        description=(
            "Pick up the pan and place it in the sink, put the sponge in the pan, "
            "then turn on the sink."
        ),
        group="presoak_pan",
        objects=[
            ObjectSpec(name="pan", body=item_body(pan), sites=pan_sites),
            ObjectSpec(name="sponge", body=item_body(sponge)),
            handle,
        ],
        goals={
            "sink": GoalSpec(kind="body", body="Sink_basin", offset=PAN_IN_SINK),
            "pan": GoalSpec(kind="body", body=pan_sites[INSIDE_SITE]),
            "knob_turned": turned,
        },
        subtasks=subtasks,
        levels=levels,
        milestones=milestones,
        qa_templates=qa,
        expert="kitchen_chain",  # pan, sponge, then the faucet task's dial expert
        max_expert_steps=1000,
    )


TASKS: list[TaskSpec] = [arrange_vegetables(), pre_soak_pan()]
