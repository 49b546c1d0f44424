"""Kitchen composites into openings: RestockPantry and PrepareCoffee (spec, levels, QA)
and what they added to the composite env (items of the forward-grasp table, start spots
beside the fixture in use, the coffee button as the scene's joint), in real MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import Event, FrameFacts, ObjectFacts
from rover.sim.kitchen.forward_items import item_instances
from rover.sim.milestones import level_problems
from rover.sim.tasks import get_task


def prepare_coffee():
    return get_task("kitchen.PrepareCoffee")


PANTRY = ("first pantry item", "second pantry item")


def test_restock_pantry_has_table5_levels_app_n_subtasks_and_c3_questions():
    spec = get_task("kitchen.RestockPantry")
    assert spec.frames == 60 and spec.group == "restock_pantry"
    assert [s.name for s in spec.subtasks] == [
        "pick up the first pantry item",
        "place the first pantry item in the cabinet",
        "pick up the second pantry item",
        "place the second pantry item in the cabinet",
    ]
    assert [s.end_signal for s in spec.subtasks[1::2]] == [f"placed:{o}" for o in PANTRY]
    assert [lv.name for lv in spec.levels] == [
        "Fail to pick up the first item",
        "Pick up the first item and place it in the pantry",
        "Pick up the second item and place it in the pantry",
    ]
    assert spec.milestones == [f"place:{o}" for o in PANTRY]
    assert spec.levels[-1].completes and spec.levels[0].terminal_grip == "open"
    assert [q.text for q in spec.qa_templates] == [
        f"Did the robot {verb} the {o}{where}? If so, when?"
        for o in PANTRY
        for verb, where in (("pick up", ""), ("drop", ""), ("place", " in the cabinet"))
    ]
    assert len(spec.paraphrases) == 3
    # two goal points in the compartment, the first item's behind the second's
    back, front = (spec.goals[g.goal[5:]] for g in spec.subtasks[1::2])
    assert back.body == front.body == "Cabinet_inside" and back.offset[0] > front.offset[0]
    assert spec.env_kwargs["level_start"] is True and spec.expert == "kitchen_forward_chain"


def test_prepare_coffee_has_table5_levels_app_n_subtasks_and_c3_questions():
    spec = prepare_coffee()
    assert spec.frames == 60 and spec.group == "prepare_coffee"
    assert [s.end_signal for s in spec.subtasks] == [
        "lifted:mug",
        "placed:mug",
        "touched:button",
        "pressed:button",
    ]
    assert spec.subtasks[-1].joint == "joint:button"  # progress follows the button's travel
    assert [lv.name for lv in spec.levels] == [
        "Fail to pick up the mug",
        "Pick up the mug and place it in the coffee machine",
        "Press the start button on the coffee machine",
    ]
    assert spec.milestones == ["place:mug", "press:button"]
    assert [q.text for q in spec.qa_templates] == [
        "Did the robot pick up the mug? If so, when?",
        "Did the robot drop the mug? If so, when?",
        "Did the robot place the mug in the coffee machine? If so, when?",
        "Did the robot press the coffee machine start button? If so, when?",
    ]
    assert spec.env_kwargs["articulated"] is True and len(spec.paraphrases) == 3


def test_coffee_levels_are_components_every_earlier_one_achieved():
    spec = prepare_coffee()
    ms = spec.milestones

    def f(mug=None, held=None, button=0.0) -> FrameFacts:
        return FrameFacts(
            holding=held, objects={"mug": ObjectFacts(on=mug)}, articulations={"button": button}
        )

    start = f("counter")
    placed = [start, f(None, "mug"), f("coffee machine")]
    pressed = [*placed, f("coffee machine", button=1.0)]
    press = [Event(name="press", object="button", frame=len(pressed) - 1)]
    assert level_problems(1, ms, [start, start], []) == []
    assert level_problems(1, ms, placed, [])  # shows the component it fails
    assert level_problems(2, ms, placed, []) == []
    assert level_problems(2, ms, pressed, press)
    assert level_problems(3, ms, pressed, press) == []
    assert level_problems(3, ms, placed, [])  # the top level must press


@pytest.mark.sim
def test_pantry_items_come_from_the_forward_table_and_stand_beside_the_cabinet(sim_env):
    """The two items are different instances of the level-hand table (a bean can, a jam
    jar, a juice carton), shown, resting on the counter on the cabinet's +y side (their
    spot follows the cabinet's drawn place), the front one first; the door stands open."""
    from rover.sim.kitchen.fixtures import FIXTURES

    pantry = sim_env("kitchen.RestockPantry")
    env = pantry.env
    names = {i.name for i in item_instances("pantry item")}
    edge_gaps = []
    for seed in range(3):
        pantry.reset(seed)
        objs = env.scene.to_json()["objects"]
        assert [o["role"] for o in objs] == list(PANTRY)
        assert {o["name"] for o in objs} <= names and objs[0]["name"] != objs[1]["name"]
        cab = env.scene.layout["Cabinet"]
        for role, obj in zip(PANTRY, objs, strict=True):
            assert env.object_place(role) == ("on", "counter")
            m, geoms = env.sim.model._model, env.role_geoms[role].ids
            assert any(m.geom_contype[g] for g in geoms[obj["name"]])  # the drawn one collides
            hidden = [g for name, gs in geoms.items() if name != obj["name"] for g in gs]
            assert hidden and not any(m.geom_contype[g] for g in hidden)  # the others do not
            edge_gaps.append(obj["qpos"][1] - cab.y - FIXTURES["Cabinet"].half_width)
        assert objs[0]["qpos"][0] < objs[1]["qpos"][0] - 0.05  # the first stands in front
        door = env.sim.data.qpos[env.joint_qpos_addr]
        assert door == pytest.approx(get_task("kitchen.RestockPantry").env_kwargs["start_q"])
        start = [pantry.point(r) for r in PANTRY]
        hold = np.zeros(len(pantry.action_low))
        for _ in range(10):
            pantry.step(hold)
        assert all(
            np.linalg.norm(pantry.point(r) - p) < 0.005 for r, p in zip(PANTRY, start, strict=True)
        )
    assert all(0.09 <= g <= 0.14 for g in edge_gaps), edge_gaps


@pytest.mark.sim
def test_coffee_button_is_the_scenes_joint_and_success_needs_both(sim_env):
    from rover.sim.facts import frame_facts

    sim = sim_env("kitchen.PrepareCoffee")
    env = sim.env
    sim.reset(0)
    assert env.part == "button" and frame_facts(sim).articulations == {"button": 0.0}
    assert env.object_place("mug") == ("on", "counter")
    env.sim.data.qpos[env.joint_qpos_addr] = env.target  # the button held down
    env.sim.forward()
    assert sim.predicate("pressed:button") and "button" in frame_facts(sim).pressed
    assert not env._check_success()  # the mug is still on the counter
