"""The composite kitchen tasks whose items go behind an opening (paper Tables 4 and 5).

RestockPantry puts two pantry items from the counter into the cabinet, PrepareCoffee
puts the mug under the coffee machine's spout and presses the machine's start button.
Both carry their items with the forward (level-hand) grasp of
`rover.sim.kitchen.forward_grasp` (the cabinet's compartment is 15 cm high, the gap under
the spout 21 cm: the top-down hand does not fit), so the arm starts in its level-hand
ready pose (``level_start``) and the expert is `rover.sim.kitchen.forward_chain`'s.

As in `rover.sim.kitchen.composites`: the subtasks (App. N) are the chained atomic
tasks' in order, the levels Table 5's row for the group, one component each
(`pick_first_levels`: cut between the demo's components by milestone, level 1
leaving the expert early on its way to the first item). Items are named by
role ("the first pantry item"); the drawn instances (a bean can, a jam jar, ...) are
recorded in ``episode.json`` under ``extra.scene.objects``.
"""

from __future__ import annotations

from rover.sim.kitchen.composites import pick_and_place, pick_first_levels
from rover.sim.kitchen.language import PARAPHRASES
from rover.sim.kitchen.utensils import ItemRole, item_body
from rover.sim.part_travel import BUTTON_TARGET
from rover.sim.tasks._common import joint_subtask, part_spec, pick_place_qa, touch_subtask
from rover.sim.tasks.base import GoalSpec, ObjectSpec, QATemplate, SubtaskSpec, TaskSpec

SUITE = "kitchen"
CABINET_OPEN = 1.7  # rad the cabinet door stands open (as PickPlaceCounterToCab's)
# the two goal spots in the cabinet's lower compartment, one behind the other (world
# offsets from its `inside` site; the cabinet's yaw is within 0.1 rad): the compartment
# is 26 cm wide and the level hand 20 cm across its fingers, so two items side by side
# leave the hand no room beside the first; the first goes to the back, the second in front
BACK_SPOT = (0.035, 0.0, 0.0)
FRONT_SPOT = (-0.045, 0.0, 0.0)


def _spec(name: str, **fields) -> TaskSpec:
    return TaskSpec(
        name=f"{SUITE}.{name}",
        env_name="RoverKitchenComposite",
        suite=SUITE,
        paraphrases=PARAPHRASES.get(name, []),
        frames=60,
        expert="kitchen_forward_chain",
        **fields,
    )


def _qa(role: ItemRole, where: str) -> list[QATemplate]:
    """App. C.3's pick up / drop / place questions of one item (no contact question)."""
    return [q for q in pick_place_qa(role.name, where) if q.id != "did_contact"]


def restock_pantry() -> TaskSpec:
    """Two pantry items (two different instances) from the counter into the cabinet."""
    where = "in the cabinet"
    roles = [  # the front one first: the hand never reaches past one item for the other
        ItemRole("first pantry item", "pantry item", "beside fixture front", "cabinet"),
        ItemRole("second pantry item", "pantry item", "beside fixture back", "cabinet"),
    ]
    goals = {
        "cabinet_back": GoalSpec(kind="body", body="Cabinet_inside", offset=BACK_SPOT),
        "cabinet_front": GoalSpec(kind="body", body="Cabinet_inside", offset=FRONT_SPOT),
    }
    subtasks = [
        *pick_and_place(roles[0], where, "goal:cabinet_back"),
        *pick_and_place(roles[1], where, "goal:cabinet_front"),
    ]
    milestones = [f"place:{r.name}" for r in roles]
    levels = pick_first_levels(
        [
            "Fail to pick up the first item",
            "Pick up the first item and place it in the pantry",
            "Pick up the second item and place it in the pantry",
        ],
        [2, 2],
        milestones,
    )
    return _spec(
        "RestockPantry",
        env_kwargs={
            "fixture": "Cabinet",
            "part": "door",
            "start_q": CABINET_OPEN,
            "level_start": True,
            "items": [[r.name, r.category, r.start, r.goal] for r in roles],
        },
        description="Pick up the two pantry items from the counter and put them in the cabinet.",
        group="restock_pantry",
        objects=[ObjectSpec(name=r.name, body=item_body(r)) for r in roles],
        goals=goals,
        subtasks=subtasks,
        levels=levels,
        milestones=milestones,
        qa_templates=[q for r in roles for q in _qa(r, where)],
        max_expert_steps=900,
    )


def _start_button() -> tuple[ObjectSpec, list[SubtaskSpec], QATemplate]:
    """The coffee machine's start button as CoffeePressButton has it: the part, its two
    subtasks (reach it, press it down; progress follows its joint) and App. C.3's question."""
    obj = "button"
    part = part_spec(obj, "Coffee", "button", "top", top="top")
    subtasks = [
        touch_subtask(
            "reach the coffee machine's start button", obj, f"{obj}:top", f"touched:{obj}"
        ),
        joint_subtask(
            "press the button down", obj, f"{obj}:top", "goal:button_pressed", f"pressed:{obj}"
        ),
    ]
    qa = QATemplate(
        id="did_press",
        text="Did the robot press the coffee machine start button? If so, when?",
        event="press",
        object=obj,
    )
    return part, subtasks, qa


def prepare_coffee() -> TaskSpec:
    """The mug from the counter under the coffee machine's spout, then its start button."""
    where = "in the coffee machine"
    mug = ItemRole("mug", "mug", "beside fixture", "coffee machine")
    button, button_subtasks, press_q = _start_button()
    milestones = ["place:mug", "press:button"]
    levels = pick_first_levels(
        [
            "Fail to pick up the mug",
            "Pick up the mug and place it in the coffee machine",
            "Press the start button on the coffee machine",
        ],
        [2, 2],
        milestones,
    )
    return _spec(
        "PrepareCoffee",
        env_kwargs={
            "fixture": "Coffee",
            "part": "button",
            "target": BUTTON_TARGET,  # as CoffeePressButton
            "articulated": True,
            "level_start": True,
            "items": [[mug.name, mug.category, mug.start, mug.goal]],
        },
        description=(
            "Pick up the mug, place it under the coffee machine's spout, "
            "then press the machine's start button."
        ),
        group="prepare_coffee",
        objects=[ObjectSpec(name=mug.name, body=item_body(mug)), button],
        goals={
            "slot": GoalSpec(kind="body", body="Coffee_slot"),
            "button_pressed": GoalSpec(kind="fixture", object="button", body="top"),
        },
        subtasks=[*pick_and_place(mug, where, "goal:slot"), *button_subtasks],
        levels=levels,
        milestones=milestones,
        qa_templates=[*_qa(mug, where), press_q],
        max_expert_steps=900,  # up to three presses
    )


TASKS: list[TaskSpec] = [restock_pantry(), prepare_coffee()]
