"""Scripted-expert motion: a waypoint the hand cannot reach ends the phase, not a stall."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def test_a_phase_ends_once_the_hand_is_stuck_near_an_unreachable_target(sim_env):
    from rover.sim.experts import STUCK_STEPS, Scripted
    from rover.sim.motions import OPEN, Phase

    sim = sim_env("Lift")
    sim.reset(0)
    table = float(sim.env.table_offset[2])
    below = sim.point("eef").copy()
    below[2] = table - 0.03  # 3 cm inside the table: the fingers stop on its top

    script = Scripted(sim)
    script.run(Phase(lambda: below, OPEN, tol=0.02, steps=200))
    steps = len(script.actions)
    assert steps < 120  # the old rule ran the whole budget with the hand resting on the table
    err = float(np.linalg.norm(below - sim.point("eef")))
    assert 0.02 <= err < 3 * 0.02  # stopped short of the target, within the reach band
    # the last STUCK_STEPS steps made (almost) no headway: that is why it ended
    assert steps > STUCK_STEPS

    # far from its target the hand is not "stuck", however slowly it moves: no early end
    sim.reset(0)
    far = sim.point("eef") + np.array([0.0, 0.0, -0.6])  # 60 cm down, deep in the table
    script = Scripted(sim)
    script.run(Phase(lambda: far, OPEN, tol=0.02, steps=60))
    assert len(script.actions) == 60
