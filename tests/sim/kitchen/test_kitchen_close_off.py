"""CloseSingleDoor and TurnOffMicrowave in MuJoCo: start states, facts, events, the latch."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def _video(sim, demo, n: int = 12):
    from rover.sim.facts import detect_events, facts_for_states

    picks = np.linspace(0, len(demo.states) - 1, n).round().astype(int)
    prev = demo.states[np.maximum(picks - 1, 0)]
    facts = facts_for_states(sim, demo.states[picks], prev)
    return facts, detect_events(sim.spec, facts)


def test_close_single_door_starts_open_and_closes_with_events(sim_env):
    from rover.sim.experts import run_expert

    sim = sim_env("kitchen.CloseSingleDoor")
    demo = run_expert(sim, 2)
    assert demo.success and len(demo.subtask_ends) == 2
    facts, found = _video(sim, demo)
    events = {e.name: e.frame for e in found}
    opening = [f.articulations["door"] for f in facts]
    assert opening[0] == 1.0 and opening[-1] <= 0.1  # "x% open" read the same as opening
    assert set(events) == {"contact", "grasp", "close_start", "close_finish"}
    assert events["contact"] <= events["close_start"] < events["close_finish"]
    assert opening[events["close_start"]] < 0.9 and opening[events["close_finish"]] <= 0.1
    assert sim.predicate("door_closed:door")


def test_turn_off_microwave_stop_button_latches_and_reads_as_off(sim_env):
    from rover.sim.experts import run_expert
    from rover.sim.facts import qa_items

    sim = sim_env("kitchen.TurnOffMicrowave")
    demo = run_expert(sim, 4)
    assert demo.success and len(demo.subtask_ends) == 2
    facts, found = _video(sim, demo)
    events = {e.name: e.frame for e in found}
    assert facts[0].articulations["stop button"] == 0.0 and facts[0].pressed == []
    assert facts[-1].pressed == ["stop button"]
    assert all(f.holding is None for f in facts)  # pressing a button is not holding it
    assert events["press"] == events["turn_off"] is not None and "turn_on" not in events
    answers = {q.template: q.answer for q in qa_items(sim.spec, found)}
    assert answers == {"did_press": True, "did_turn_off": True}
    # the stop button stays down once pressed (the microwave stays off); the start button
    # beside it springs back
    env = sim.env
    sim.reset(4)
    start = sim.model.joint(env.fixture.naming_prefix + "button").qposadr[0]
    sim.data.qpos[env.joint_qpos_addr] = -0.014
    sim.data.qpos[start] = -0.014
    sim.sim.forward()
    hold = np.zeros(len(sim.action_low))
    for _ in range(20):
        sim.step(hold)
    assert env.pressed() and sim.predicate("pressed:stop button")
    assert sim.data.qpos[start] > -0.005
    # untouched, it does not creep down by itself either
    sim.reset(4)
    for _ in range(20):
        sim.step(hold)
    assert abs(env.joint_value()) < 1e-3
