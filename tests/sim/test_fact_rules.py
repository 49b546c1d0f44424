"""Each fact and event rule on hand-built MuJoCo states (real robosuite models).

States are taken from a scripted expert run and then edited joint by joint (fingers
opened, an object moved), so every rule is checked on a state whose physics we know.
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def _free_qpos(sim, body: str) -> int:
    """Flat-state index (after time) of the free joint position of an object's body."""
    import mujoco

    bid = int(mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, body))
    jid = int(sim.model.body_jntadr[bid])
    return 1 + int(sim.model.jnt_qposadr[jid])


def _fingers(sim, state: np.ndarray, half_width: float) -> np.ndarray:
    s = state.copy()
    s[1 + sim._finger_qpos[0]] = half_width
    s[1 + sim._finger_qpos[1]] = -half_width
    return s


@pytest.fixture(scope="module")
def lift(sim_env):
    from rover.sim.experts import run_expert

    sim = sim_env("Lift")
    demo = run_expert(sim, 2)
    sim.begin(demo.states[0])
    return sim, demo


def _first_both(sim, states, obj):
    for t, s in enumerate(states):
        sim.set_state(s)
        if sim.grasped(obj):
            return t
    raise AssertionError("the expert never closes both fingers on the object")


def test_hold_at_table_height_needs_both_fingers_and_moving_with_hand(lift):
    from rover.sim.facts import facts_for_states

    sim, demo = lift
    t = _first_both(sim, demo.states, "cube") + 1
    pair = demo.states[t - 1 : t + 1]
    f = facts_for_states(sim, pair[1:], pair[:1])[0]
    assert f.holding == "cube" and not f.objects["cube"].lifted  # held, not yet lifted
    # the same state, but the cube was 2 cm elsewhere one step before: it is not moving
    # with the hand, so both fingers touching it is not a hold
    moved = pair[:1].copy()
    moved[0, _free_qpos(sim, "cube_main")] += 0.02
    assert facts_for_states(sim, pair[1:], moved)[0].holding is None
    # fingers opened wide: no contact, no hold
    opened = _fingers(sim, pair[1], 0.04)
    assert facts_for_states(sim, opened[None], pair[:1])[0].holding is None


def test_grasp_event_is_the_hold_beginning_not_a_touch(lift):
    from rover.episode import FrameFacts
    from rover.sim.facts import detect_events, facts_for_states

    sim, demo = lift
    facts = facts_for_states(sim, demo.states, np.concatenate([demo.states[:1], demo.states[:-1]]))
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert ev["grasp"] is not None
    assert facts[ev["grasp"]].holding == "cube" and facts[ev["grasp"] - 1].holding != "cube"
    assert ev["contact"] <= ev["grasp"] <= ev["pick_up"]
    assert ev["drop"] is None  # the expert never lets go
    # touching with a closed gripper, never holding: contact but no grasp
    touch = [FrameFacts(), FrameFacts(gripper="closed", contacts=["cube"])]
    ev2 = {e.name: e.frame for e in detect_events(sim.spec, touch)}
    assert ev2["contact"] == 1 and ev2["grasp"] is None


def test_opening_the_hand_in_the_air_is_a_drop(lift):
    from rover.sim.facts import detect_events, facts_for_states
    from rover.sim.validate import event_problems

    sim, demo = lift
    held = demo.states[-1]
    states = np.stack([demo.states[0], held, _fingers(sim, held, 0.04)])
    facts = facts_for_states(sim, states, np.stack([states[0], held, held]))
    assert facts[1].holding == "cube" and facts[2].holding is None
    events = detect_events(sim.spec, facts)
    ev = {e.name: e.frame for e in events}
    assert ev["drop"] == 2
    assert all(event_problems(e, facts) == [] for e in events)


def test_letting_go_of_an_object_never_moved_is_neither_drop_nor_place(lift):
    """Fingers closed on the cube at the table (a hold, no lift), then opened: the cube
    never left where it stood, so the release is no drop (it did not fall), no place."""
    from rover.sim.facts import detect_events, facts_for_states

    sim, demo = lift
    t = _first_both(sim, demo.states, "cube")
    before, grasped = demo.states[t - 1], demo.states[t + 1]
    states = np.stack([before, grasped, _fingers(sim, grasped, 0.04)])
    prev = np.stack([before, demo.states[t], grasped])
    facts = facts_for_states(sim, states, prev)
    assert facts[1].holding == "cube" and not facts[1].objects["cube"].lifted
    assert facts[2].holding is None
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert ev["grasp"] == 1 and ev["drop"] is None and ev["pick_up"] is None
    # the same release with the cube 3 cm off where it stood: it was taken somewhere
    moved = states.copy()
    moved[2, _free_qpos(sim, "cube_main")] += 0.03
    facts = facts_for_states(sim, moved, prev)
    assert {e.name: e.frame for e in detect_events(sim.spec, facts)}["drop"] == 2


@pytest.fixture(scope="module")
def can(sim_env):
    from rover.sim.experts import run_expert

    sim = sim_env("PickPlaceCan")
    demo = run_expert(sim, 0)
    sim.begin(demo.states[0])
    return sim, demo


def test_release_in_the_bin_is_a_place_and_lowering_held_is_not(can):
    from rover.sim.facts import detect_events, facts_for_states
    from rover.sim.validate import event_problems

    sim, demo = can
    prev = np.concatenate([demo.states[:1], demo.states[:-1]])
    facts = facts_for_states(sim, demo.states, prev)
    events = detect_events(sim.spec, facts)
    ev = {e.name: e.frame for e in events}
    assert ev["place"] is not None and ev["drop"] is None
    assert facts[ev["place"] - 1].holding == "can" and facts[ev["place"]].holding is None
    # while lowered into the bin the can is held below the pick-up height: still held
    low = [f for f in facts if f.holding == "can" and not f.objects["can"].lifted]
    assert low, "the expert should hold the can at some frame below 4 cm over its start"
    assert all(event_problems(e, facts) == [] for e in events)


def test_untouched_object_stays_put_in_a_physical_recovery(can):
    """drive_robot moves the arm; a can resting on the table does not rise or slide."""
    sim, demo = can
    sim.reset(0)
    a = sim.get_state()
    b = demo.states[len(demo.states) // 3].copy()
    sim.set_state(a)
    before = sim.point("can").copy()
    for z in range(1, 6):
        sim.drive_robot(a, b, (z - 1) / 5, z / 5)
    sim_state = sim.get_state()
    assert np.allclose(sim_state[1 + sim.robot_qpos], b[1 + sim.robot_qpos], atol=1e-6)
    assert np.linalg.norm(sim.point("can") - before) < 0.005


def test_knob_joint_fraction_and_facts_follow_the_joint(sim_env):
    from rover.sim.facts import frame_facts

    sim = sim_env("TurnKnob")
    sim.reset(0)
    fx = sim.env
    span = fx.target - fx.start_q
    seen = []
    for frac in (0.0, 0.25, 0.5, 1.0):
        s = sim.get_state()
        s[1 + fx.joint_qpos_addr] = fx.start_q + frac * span
        sim.set_state(s)
        seen.append((sim.joint_fraction("knob"), frame_facts(sim).articulations["knob"]))
    assert [round(a, 2) for a, _ in seen] == [0.0, 0.25, 0.5, 1.0]
    assert [b for _, b in seen] == sorted(b for _, b in seen) and seen[-1][1] == 1.0


def test_letting_go_off_the_goal_is_a_drop_and_in_it_a_place(can):
    """The same release, once with the can resting in its bin and once with it set back on
    the table: place in the first, drop in the second (the goal region decides)."""
    from rover.sim.facts import detect_events, facts_for_states

    sim, demo = can
    prev = np.concatenate([demo.states[:1], demo.states[:-1]])
    facts = facts_for_states(sim, demo.states, prev)
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    held, let_go = demo.states[ev["place"] - 1], demo.states[ev["place"]]
    on_table = let_go.copy()
    qa = _free_qpos(sim, "Can_main")
    on_table[qa : qa + 3] = demo.states[0][qa : qa + 3]  # back where it started
    for end, kind in ((let_go, "place"), (on_table, "drop")):
        states = np.stack([demo.states[0], held, end])
        f = facts_for_states(sim, states, np.stack([states[0], prev[ev["place"] - 1], held]))
        assert f[1].holding == "can" and f[2].holding is None
        got = {e.name: e.frame for e in detect_events(sim.spec, f)}
        other = "drop" if kind == "place" else "place"
        assert got[kind] == 2 and got[other] is None, (kind, got)


def _set_joint(sim, fraction_of_way: float) -> None:
    fx = sim.env
    s = sim.get_state()
    s[1 + fx.joint_qpos_addr] = fx.start_q + fraction_of_way * (fx.target - fx.start_q)
    sim.set_state(s)


def test_closing_drawer_fact_is_its_opening_and_events_follow_it(sim_env):
    """CloseDrawer: the joint fraction counts toward closed, the fact says how far open;
    close_start fires once it is under 90% open, close_finish at 10% open or less."""
    from rover.sim.facts import detect_events, frame_facts

    sim = sim_env("CloseDrawer")
    sim.reset(0)
    facts = []
    for way in (0.0, 0.05, 0.3, 0.6, 0.95):
        _set_joint(sim, way)
        assert sim.joint_fraction("drawer") == pytest.approx(way, abs=1e-6)
        facts.append(frame_facts(sim))
    opening = [f.articulations["drawer"] for f in facts]
    assert opening[0] == 1.0 and opening == sorted(opening, reverse=True)
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts) if e.object == "drawer"}
    assert ev["close_start"] == 2 and ev["close_finish"] == 4
    assert ev["grasp"] is None  # nothing held the handle


def test_button_is_pressed_only_past_its_switching_depth(sim_env):
    from rover.sim.facts import detect_events, frame_facts

    sim = sim_env("PressButton")
    sim.reset(0)
    facts = []
    for way in (0.0, 0.5, 0.85, 0.95):  # switching depth = 90% of the way
        _set_joint(sim, way)
        facts.append(frame_facts(sim))
    assert [("button" in f.pressed) for f in facts] == [False, False, False, True]
    assert [f.articulations["button"] for f in facts] == [0.0, 0.0, 0.0, 1.0]
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts)}
    assert ev["press"] == ev["turn_on"] == 3


def test_door_fact_is_the_hinge_fraction_and_opening_events_follow_it(sim_env):
    from rover.sim.facts import detect_events, frame_facts

    sim = sim_env("Door")
    sim.reset(0)
    goal = sim.spec.goals["door_open"].angle
    facts = []
    for frac in (0.0, 0.02, 0.3, 0.95):
        s = sim.get_state()
        s[1 + sim.env.hinge_qpos_addr] = frac * goal
        sim.set_state(s)
        assert sim.joint_fraction("door") == pytest.approx(frac, abs=1e-6)
        facts.append(frame_facts(sim))
    assert [f.articulations["door"] for f in facts] == [0.0, 0.02, 0.3, 0.95]
    ev = {e.name: e.frame for e in detect_events(sim.spec, facts) if e.object == "door"}
    assert ev["open_start"] == 2 and ev["open_finish"] == 3 and ev["grasp"] is None
