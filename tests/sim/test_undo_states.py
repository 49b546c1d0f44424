"""The undo rule of the progress value on hand-built MuJoCo states (PickPlaceCan).

States come from one scripted expert run and are then edited joint by joint (the can put
back on the table, the fingers opened), so the rule is checked on states whose physics we
know: a can dropped after its pick-up returns progress to the pick-up stage, valued by
where the hand is; the paper's form keeps the pick-up's credit.
"""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def _free_qpos(sim, body: str) -> int:
    """Flat-state index (after time) of the free joint position of an object's body."""
    import mujoco

    bid = int(mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_BODY, body))
    return 1 + int(sim.model.jnt_qposadr[int(sim.model.body_jntadr[bid])])


def _open(sim, state: np.ndarray) -> np.ndarray:
    s = state.copy()
    s[1 + sim._finger_qpos[0]] = 0.04
    s[1 + sim._finger_qpos[1]] = -0.04
    return s


@pytest.fixture(scope="module")
def can(sim_env):
    from rover.sim.experts import run_expert
    from rover.sim.perturb import bounds_from_ends

    sim = sim_env("PickPlaceCan")
    demo = run_expert(sim, 0)
    assert demo.success
    sim.begin(demo.states[0])
    return sim, demo.states, bounds_from_ends(demo.subtask_ends, len(demo.states))


def _progress(sim, spec, expert, bounds, states, q, form="rover"):
    from rover.sim.value import point_tracks, progress_from_tracks, required_points

    names = required_points(spec.subtasks)
    signals = [s.end_signal for s in spec.subtasks]
    ex = point_tracks(sim, expert, names)
    roll = point_tracks(sim, np.stack(states), names, signals)
    return progress_from_tracks(roll, np.asarray(q), ex, spec.subtasks, bounds, form=form)


def test_a_dropped_can_returns_progress_to_the_pick_up_stage(can):
    sim, states, bounds = can
    spec = sim.spec
    lifted = bounds[0][1]  # the expert's pick-up: the can held and lifted
    grasp = next(t for t in range(lifted) if _grasped(sim, states[t]))
    carry = (bounds[1][0] + bounds[1][1]) // 2  # half way to the bin
    start = states[0][_free_qpos(sim, "Can_main") : _free_qpos(sim, "Can_main") + 7]

    def can_back(state):  # the can at rest where it started, the fingers open
        s = _open(sim, state)
        s[_free_qpos(sim, "Can_main") : _free_qpos(sim, "Can_main") + 7] = start
        return s

    # released at the lift with the hand still at it; dropped with the hand over the bin
    at_hand, away = can_back(states[grasp]), can_back(states[carry])
    seq = [states[0], states[grasp], states[lifted], states[carry], at_hand, away]
    q = [0, grasp, lifted, carry, carry, carry]
    rover = _progress(sim, spec, states, bounds, seq, q)
    paper = _progress(sim, spec, states, bounds, seq, q, form="paper")
    assert rover[3] > rover[2] >= 0.45  # carrying: past the pick-up stage
    # both undo the pick-up: valued in its stage, by the hand's distance to the can
    assert rover[4] < rover[2] and rover[5] < rover[4]
    assert rover[4] == pytest.approx(rover[1], abs=0.05)  # as when the expert grasped it
    assert rover[5] < rover[1] - 0.1  # the hand is far off: well below the grasp
    # the paper's form keeps the pick-up's credit for a can lying on the table
    assert paper[4] >= paper[2] - 1e-9 and paper[5] >= paper[2] - 1e-9


def test_a_finger_brushing_a_can_on_the_table_does_not_keep_the_pick_up(can):
    """The pick-up stands while the can is held, or lifted with a finger on it: one finger
    left touching a can back on the table is not "picked up" (it used to read 0.50)."""
    sim, states, bounds = can
    lifted = bounds[0][1]
    sim.set_state(states[lifted])
    assert sim.kept("lifted:can")
    grasp = next(t for t in range(lifted) if _grasped(sim, states[t]))
    sim.set_state(states[grasp])  # both fingers on the can at table height: a grasp
    assert sim.kept("lifted:can") and not sim.lifted("can")
    left, right = (sim.data.geom_xpos[sim._pad_geoms[k]].copy() for k in ("left", "right"))
    toward = (left - right) / np.linalg.norm(left - right)
    s = states[grasp].copy()
    i = _free_qpos(sim, "Can_main")
    s[i : i + 2] += 0.006 * toward[:2]  # pressed against the left finger only
    sim.set_state(s)
    assert set(sim.finger_contacts().get("can", ())) == {"left"}
    assert not sim.kept("lifted:can")


def _grasped(sim, state) -> bool:
    sim.set_state(state)
    return sim.grasped("can")
