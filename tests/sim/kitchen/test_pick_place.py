"""Kitchen pick-and-place: regions, the seeded item, and its facts and events in MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.sim.kitchen.fixtures import COUNTER_TOP
from rover.sim.kitchen.regions import locate, to_local, to_world
from rover.sim.milestones import achieved

SINK_AT = (np.array([-0.08, -0.1, COUNTER_TOP]), 0.1)


def _world(local, pose=SINK_AT):
    return to_world(np.asarray(local, dtype=np.float64), *pose)


def test_regions_tell_basin_counter_deck_and_air_apart():
    poses = {"Sink": SINK_AT}
    assert np.allclose(to_local(_world([0.03, -0.05, 0.02]), *SINK_AT), [0.03, -0.05, 0.02])
    # resting on the basin floor (1 cm up), or let go 3 cm above it: inside the sink
    ball = 0.03
    for lift in (0.0, 0.03):
        centre = _world([-0.05, 0.04, 0.01 + ball + lift])
        assert locate(centre, centre[2] - ball, poses) == ("inside", "sink")
    # above the rim (carried over it): nowhere
    centre = _world([-0.05, 0.04, 0.16])
    assert locate(centre, centre[2] - ball, poses) is None
    # on the faucet deck behind the basin: on the sink's footprint, not in a region
    centre = _world([0.16, 0.0, 0.1 + ball])
    assert locate(centre, centre[2] - ball, poses) is None
    # on a stove's cooktop (4 cm high) standing beside the sink
    stove = (np.array([0.15, 0.3, COUNTER_TOP]), -0.2)
    centre = _world([0.0, -0.1, 0.04 + ball], stove)
    assert locate(centre, centre[2] - ball, {**poses, "Stove": stove}) == ("on", "stove")
    assert locate(centre, centre[2] - ball, poses) != ("on", "stove")
    # on the free counter beside it, and falling from 10 cm above the counter
    centre = np.array([-0.1, 0.25, COUNTER_TOP + ball])
    assert locate(centre, centre[2] - ball, poses) == ("on", "counter")
    centre[2] += 0.1
    assert locate(centre, centre[2] - ball, poses) is None


def _facts(inside=None, on=None, held=False) -> FrameFacts:
    return FrameFacts(
        holding="vegetable" if held else None,
        objects={"vegetable": ObjectFacts(inside=inside, on=on)},
    )


def test_place_milestone_needs_a_region_other_than_the_start():
    """An item starting inside the sink is not "placed" by lying there; on the counter it is."""
    start_in_sink = [_facts(inside="sink"), _facts(held=True), _facts(inside="sink")]
    assert not achieved("place:vegetable", start_in_sink, [])
    moved = [_facts(inside="sink"), _facts(held=True), _facts(on="counter")]
    assert achieved("place:vegetable", moved, [])
    on_counter = [_facts(on="counter"), _facts(held=True), _facts(on="counter")]
    assert not achieved("place:vegetable", on_counter, [])


def test_audit_reads_a_release_back_at_the_start_as_a_drop_not_a_place():
    from rover.episode import Event
    from rover.sim.validate import event_problems

    facts = [_facts(on="counter"), _facts(held=True), _facts(on="counter")]
    assert event_problems(Event(name="drop", object="vegetable", frame=2), facts) == []
    assert event_problems(Event(name="place", object="vegetable", frame=2), facts)
    away = [_facts(on="counter"), _facts(held=True), _facts(inside="sink")]
    assert event_problems(Event(name="place", object="vegetable", frame=2), away) == []
    assert event_problems(Event(name="drop", object="vegetable", frame=2), away)


@pytest.fixture(scope="module")
def to_sink(sim_env):
    return sim_env("kitchen.PickPlaceCounterToSink")


@pytest.mark.sim
def test_item_instance_is_drawn_per_seed_and_switched_on_alone(to_sink):
    env, m = to_sink.env, to_sink.model
    seen = set()
    for seed in range(10):
        to_sink.reset(seed)
        item = env.scene.item
        seen.add(item["name"])
        assert env.scene.to_json()["item"] == item  # recorded with the scene
        assert env.item_place() == ("on", "counter")
        for name, geoms in env.item_geoms.ids.items():
            colliding = [bool(m.geom_contype[g] or m.geom_conaffinity[g]) for g in geoms]
            assert any(colliding) == (name == item["name"])
        # it rests: a few still steps leave it where it started
        start = to_sink.point("vegetable")
        hold = np.zeros(len(to_sink.action_low))
        for _ in range(10):
            to_sink.step(hold)
        assert np.linalg.norm(to_sink.point("vegetable") - start) < 0.005
    assert len(seen) >= 3  # several instances of the category
    to_sink.reset(4)
    first = dict(to_sink.env.scene.item)
    to_sink.reset(4)
    assert to_sink.env.scene.item == first


@pytest.mark.sim
def test_expert_places_the_item_in_the_sink_and_events_say_place(to_sink):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    demo = run_expert(to_sink, 1)
    assert demo.success and len(demo.subtask_ends) == 2
    picks = np.linspace(0, len(demo.states) - 1, 30).round().astype(int)
    previous = demo.states[np.maximum(picks - 1, 0)]
    facts = facts_for_states(to_sink, demo.states[picks], previous)
    assert facts[0].objects["vegetable"].on == "counter"
    assert facts[-1].objects["vegetable"].inside == "sink"
    events = {e.name: e.frame for e in detect_events(to_sink.spec, facts)}
    assert events["pick_up"] is not None and events["place"] is not None
    assert events["drop"] is None
    assert events["pick_up"] < events["place"]
    assert achieved("place:vegetable", facts, detect_events(to_sink.spec, facts))
