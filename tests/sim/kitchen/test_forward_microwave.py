"""Kitchen pick-and-place through an opening: the microwave, cabinet and coffee-machine
regions, the forward-grasp items, the level-hand start and the forward expert in MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.kitchen.fixtures import COUNTER_TOP
from rover.sim.kitchen.forward_items import FORWARD_CATALOGUE, item_instances
from rover.sim.kitchen.objects import half_height
from rover.sim.kitchen.regions import locate, to_world

MICROWAVE_AT = (np.array([0.1, -0.1, COUNTER_TOP]), -0.15)


def test_microwave_cavity_is_inside_the_microwave_and_its_roof_is_not():
    poses = {"Microwave": MICROWAVE_AT}
    half = 0.04
    for lift in (0.0, 0.03):  # resting on the cavity floor (1 cm up), or let go just above
        centre = to_world(np.array([-0.02, -0.06, 0.01 + half + lift]), *MICROWAVE_AT)
        assert locate(centre, centre[2] - half, poses) == ("inside", "microwave")
    # carried level through the cavity (bottom 6 cm over its floor): in no region yet
    centre = to_world(np.array([-0.02, -0.06, 0.07 + half]), *MICROWAVE_AT)
    assert locate(centre, centre[2] - half, poses) is None
    # standing on the microwave's roof, or on the control panel's side of the divider
    centre = to_world(np.array([0.0, -0.05, 0.2 + half]), *MICROWAVE_AT)
    assert locate(centre, centre[2] - half, poses) is None
    centre = to_world(np.array([0.0, 0.14, 0.01 + half]), *MICROWAVE_AT)
    assert locate(centre, centre[2] - half, poses) is None


def test_forward_items_fit_the_open_hand_at_any_yaw_and_stand_above_its_palm():
    """Fingers open 8 cm; the palm's lower edge is 3.5 cm above the surface when the
    fingers are level with the item's centre, so the item must stand taller than 7 cm."""
    assert len(item_instances("food container")) >= 3
    assert len({i.rgba for i in item_instances("food container")}) == len(
        item_instances("food container")
    )
    for inst in FORWARD_CATALOGUE:
        round_ = inst.shape in ("cylinder", "mug")
        across = 2 * inst.size[0] if round_ else 2 * np.hypot(*inst.size[:2])
        assert across <= 0.064, inst.name
        assert 2 * half_height(inst) >= 0.07, inst.name
    assert item_instances("vegetable")[0].name == "tomato"  # the catalogue's, unchanged


def test_cabinet_compartment_and_coffee_tray_regions():
    cabinet = (np.array([0.15, -0.08, COUNTER_TOP]), 0.08)
    half = 0.04
    centre = to_world(np.array([-0.02, 0.01, 0.01 + half + 0.01]), *cabinet)
    assert locate(centre, centre[2] - half, {"Cabinet": cabinet}) == ("inside", "cabinet")
    # on the shelf above the compartment: in no region
    centre = to_world(np.array([-0.02, 0.01, 0.169 + half]), *cabinet)
    assert locate(centre, centre[2] - half, {"Cabinet": cabinet}) is None
    coffee = (np.array([0.1, 0.0, COUNTER_TOP]), -0.1)
    centre = to_world(np.array([-0.04, 0.0, 0.02 + half]), *coffee)
    assert locate(centre, centre[2] - half, {"Coffee": coffee}) == ("on", "coffee machine")
    # on the tray's front edge, 7 cm in front of the spout: not under it
    centre = to_world(np.array([-0.11, 0.0, 0.02 + half]), *coffee)
    assert locate(centre, centre[2] - half, {"Coffee": coffee}) is None


def test_each_forward_category_has_three_told_apart_instances():
    for category in ("food container", "pantry item", "mug"):
        found = item_instances(category)
        assert len(found) >= 3
        assert len({(i.size, i.rgba) for i in found}) == len(found)
        assert len({i.name for i in found}) == len(found)


@pytest.fixture(scope="module")
def to_microwave(sim_env):
    return sim_env("kitchen.PickPlaceCounterToMicrowave")


@pytest.mark.sim
def test_microwave_door_stands_open_and_is_recorded(to_microwave):
    to_microwave.reset(3)
    env = to_microwave.env
    assert env.joint_value() == pytest.approx(1.85, abs=1e-6)
    assert env.scene.to_json()["item"]["door"] == pytest.approx(1.85)
    assert env.scene.item["name"] in {i.name for i in item_instances("food container")}
    assert env.item_place() == ("on", "counter")
    # the arm starts in the level-hand ready pose, the item's counter spot clear of it
    approach = to_microwave.data.site_xmat[to_microwave._eef_site].reshape(3, 3)[:, 2]
    assert abs(approach[2]) < 0.05 and approach[0] > 0.95
    hand = to_microwave.point("eef")
    assert np.linalg.norm((hand - to_microwave.point("food container"))[:2]) > 0.1


@pytest.mark.sim
@pytest.mark.parametrize(
    "task, start, goal",
    [
        ("kitchen.PickPlaceCounterToMicrowave", ("on", "counter"), ("inside", "microwave")),
        ("kitchen.PickPlaceMicrowaveToCounter", ("inside", "microwave"), ("on", "counter")),
        ("kitchen.PickPlaceCounterToCab", ("on", "counter"), ("inside", "cabinet")),
        ("kitchen.CoffeeServeMug", ("on", "coffee machine"), ("on", "counter")),
    ],
)
def test_forward_expert_moves_the_item_through_the_opening(sim_env, task, start, goal):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    sim = sim_env(task)
    demo = run_expert(sim, 1)
    assert demo.success and len(demo.subtask_ends) == 2
    picks = np.linspace(0, len(demo.states) - 1, 30).round().astype(int)
    previous = demo.states[np.maximum(picks - 1, 0)]
    facts = facts_for_states(sim, demo.states[picks], previous)
    obj = sim.spec.objects[0].name
    first, last = facts[0].objects[obj], facts[-1].objects[obj]
    assert (first.inside or None, first.on or None) == (
        start[1] if start[0] == "inside" else None,
        start[1] if start[0] == "on" else None,
    )
    assert (last.inside if goal[0] == "inside" else last.on) == goal[1]
    assert facts[-1].holding is None
    events = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert events["pick_up"] is not None and events["place"] is not None
    assert events["drop"] is None and events["pick_up"] < events["place"]
    # the hand pointed forward while holding it: its approach axis is level
    sim.set_state(demo.states[demo.subtask_ends[0]])
    approach = sim.data.site_xmat[sim._eef_site].reshape(3, 3)[:, 2]
    assert abs(approach[2]) < 0.2
