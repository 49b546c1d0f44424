"""Progress of articulated tasks on real MuJoCo states: it follows the joint.

One scripted TurnKnob demonstration, trimmed as the generator trims it, then measured as
the generator measures it (`point_tracks` with the subtask signals,
`progress_from_tracks`, frames picked by `even_positions`).
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def knob(sim_env):
    from rover.sim.attempt import trim_demo
    from rover.sim.experts import run_expert
    from rover.sim.value import point_tracks, required_points

    sim = sim_env("TurnKnob")
    demo = run_expert(sim, 0)
    assert demo.success
    sim.begin(demo.states[0])
    states, _, ends = trim_demo(sim, demo.states, demo.actions, demo.subtask_ends)
    spec = sim.spec
    signals = [s.end_signal for s in spec.subtasks]
    tracks = point_tracks(sim, states, required_points(spec.subtasks), signals)
    return sim, states, ends, tracks


def _progress(tracks, q, expert, spec, ends, form="rover"):
    from rover.sim.perturb import bounds_from_ends
    from rover.sim.value import progress_from_tracks

    bounds = bounds_from_ends(ends, len(expert))
    return progress_from_tracks(
        tracks, q, expert, spec.subtasks, bounds, goal_end=int(ends[-1]), form=form
    )


def test_expert_progress_rises_with_the_knob_angle_over_the_turn(knob):
    from rover.episode import even_positions
    from rover.sim.audit import joint_lags
    from rover.sim.facts import facts_for_states

    sim, states, ends, tracks = knob
    prog = _progress(tracks, np.arange(len(states)), tracks, sim.spec, ends)
    pos = even_positions(len(states), 30)
    angle = tracks.points["joint:knob"][pos, 0]
    p = prog[pos]
    turning = np.flatnonzero((angle > 0.1) & (angle < 0.9))
    # the trim keeps the turn (the knob turns on its axis: no point of it moves)
    assert len(turning) >= 4, angle
    a, b = turning[0] - 1, turning[-1] + 1
    assert p[b] - p[a] >= 0.25
    assert np.all(np.diff(p[a : b + 1]) > -0.01)  # monotone while it turns
    assert np.corrcoef(angle[a : b + 1], p[a : b + 1])[0, 1] > 0.95
    facts = facts_for_states(sim, states[pos])
    assert joint_lags(facts, list(p)) == []


def test_a_turn_finished_off_the_expert_path_is_valued_done(knob):
    """A rollout that branched off during the grasp (q stays there) but whose state shows
    the knob turned all the way is done in rover's form; the paper's form caps it at the
    grasp subtask's share."""
    sim, states, ends, tracks = knob
    grasp_end = int(ends[0])
    idx = np.concatenate([np.arange(grasp_end - 5), [len(states) - 1] * 3])
    q = np.minimum(idx, grasp_end - 6)  # every step after the branch point keeps its q
    roll = tracks.take(idx)
    assert roll.reached["turned:knob"][-1] and not roll.reached["turned:knob"][0]
    rover = _progress(roll, q, tracks, sim.spec, ends)
    paper = _progress(roll, q, tracks, sim.spec, ends, form="paper")
    assert rover[-1] == pytest.approx(1.0)
    assert paper[-1] <= 0.5 + 1e-9
    assert rover[-4] == pytest.approx(paper[-4])  # before the turn: the same value
