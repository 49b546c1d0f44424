"""Levels by milestone on the real robosuite Lift task: marks, trim, first tries."""

from __future__ import annotations

import pytest

from rover.episode import StateType

pytest.importorskip("mujoco")
pytest.importorskip("robosuite")

pytestmark = [pytest.mark.sim]


@pytest.fixture(scope="module")
def lift(sim_env):
    from rover.sim.attempt import trim_demo
    from rover.sim.experts import run_expert

    sim = sim_env("Lift")
    demo = run_expert(sim, 1)
    assert demo.success
    sim.reset(1)
    sim.begin(demo.states[0])
    states, actions, ends = trim_demo(sim, demo.states, demo.actions, list(demo.subtask_ends))
    return sim, [(states, actions, ends, 1)], len(demo.states)


def test_trimmed_expert_never_stands_still_more_than_two_steps(lift):
    from rover.sim.audit import facts_changed
    from rover.sim.facts import facts_for_states

    sim, demos, raw_len = lift
    states = demos[0][0]
    assert len(states) < raw_len
    facts = facts_for_states(sim, states)
    still = 0
    for a, b in zip(facts, facts[1:], strict=False):
        still = 0 if facts_changed(a, b) else still + 1
        assert still <= 2


def test_marks_are_ordered_and_first_tries_meet_their_level(lift):
    from rover.sim.attempt import demo_marks, make_attempts
    from rover.sim.cuts import cut_window
    from rover.sim.tasks import get_task

    sim, demos, _ = lift
    spec = get_task("Lift")
    states = demos[0][0]
    marks = demo_marks(sim, spec, states)
    steps = [s for s in marks.steps if s is not None]
    assert len(steps) == len(spec.milestones) and steps == sorted(steps)
    approach, contact, pick = marks.steps
    (hold_start, _), *_ = marks.holds["cube"]
    assert contact <= hold_start <= pick
    levels = {lv.level: lv for lv in spec.levels}
    window = cut_window(levels[3], spec.milestones, marks, 30)
    if contact == hold_start:  # nothing touched-not-held: the demo is not used for L3
        assert window is None
    else:
        assert window[1] < hold_start
    for lv in (2, 3):
        tries = make_attempts(sim, spec, levels[lv], demos, {}, 0, lv * 10_000, 30, marks={})
        first = next((a for a in tries if not a.problems), None)
        assert first is not None, lv  # some try within MAX_TRIES shows the level
        names = {e.name: e.frame for e in first.events}
        if lv == 2:
            assert names["contact"] is None
        else:
            assert names["contact"] is not None and names["pick_up"] is None
        # the frame where the video leaves the expert is one of the sampled frames
        kinds = first.roll.state_type
        cut = max(i for i, t in enumerate(kinds) if t != StateType.non_expert)
        assert cut in first.positions
