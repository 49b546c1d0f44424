"""Facts read from the simulator agree with the events derived from them."""

from __future__ import annotations

import pytest

from rover.sim.validate import event_problems

pytestmark = pytest.mark.sim


def test_lift_expert_facts_and_events(sim_env):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states, qa_items

    sim = sim_env("Lift")
    demo = run_expert(sim, 2)
    facts = facts_for_states(sim, demo.states)
    assert facts[0].gripper == "open" and facts[0].holding is None and not facts[0].contacts
    assert facts[-1].holding == "cube" and facts[-1].gripper == "closed"
    assert facts[-1].objects["cube"].lifted and not facts[0].objects["cube"].lifted
    assert facts[0].objects["cube"].on == "table"
    assert facts[-1].distances["gripper-cube"] < facts[0].distances["gripper-cube"]
    events = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert events["contact"] is not None and events["contact"] <= events["pick_up"]
    assert events["drop"] is None
    for e in detect_events(sim.spec, facts):
        assert event_problems(e, facts) == []
    qa = {q.template: q for q in qa_items(sim.spec, detect_events(sim.spec, facts))}
    assert qa["did_pick_up"].answer and qa["did_pick_up"].frame == events["pick_up"]
    assert not qa["did_drop"].answer and qa["did_drop"].frame is None


def test_door_opening_events(sim_env):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    sim = sim_env("Door")
    demo = run_expert(sim, 0)
    facts = facts_for_states(sim, demo.states)
    assert facts[0].articulations["door"] == 0.0
    assert facts[-1].articulations["door"] >= 0.9
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert ev["contact"] <= ev["open_start"] <= ev["open_finish"]
    for e in detect_events(sim.spec, facts):
        assert event_problems(e, facts) == []
