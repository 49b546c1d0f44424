"""Trajectories and values on the real robosuite Lift task (needs the 'sim' extra)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("robosuite")

from rover.episode import Episode, GroundTruth, even_positions  # noqa: E402
from rover.sim.perturb import (  # noqa: E402
    bounds_from_ends,
    execute_plan,
    plan_trajectory,
)
from rover.sim.validate import validate_episode  # noqa: E402
from rover.sim.value import ground_truth_value, point_tracks, required_points  # noqa: E402

pytestmark = [pytest.mark.sim, pytest.mark.slow]


@pytest.fixture(scope="module")
def lift():
    env_mod = pytest.importorskip("rover.sim.env")
    experts = pytest.importorskip("rover.sim.experts")
    from rover.sim.tasks import get_task

    spec = get_task("Lift")
    sim = env_mod.SimEnv(spec)
    demo = experts.run_expert(sim, 0)
    assert demo.success
    bounds = bounds_from_ends(demo.subtask_ends, len(demo.states))
    tracks = point_tracks(sim, demo.states, required_points(spec.subtasks))
    return sim, spec, demo, bounds, tracks


def _progress(lift, rollout):
    sim, spec, demo, bounds, tracks = lift
    return ground_truth_value(
        sim, rollout.states, rollout.q, demo.states, spec.subtasks, bounds, expert_tracks=tracks
    )


def test_lift_expert_value_rises_from_0_to_1(lift):
    sim, spec, demo, bounds, tracks = lift
    n = len(demo.states)
    v = ground_truth_value(
        sim, demo.states, np.arange(n), demo.states, spec.subtasks, bounds, expert_tracks=tracks
    )
    assert v[0] == 0.0 and v[-1] == pytest.approx(1.0)
    assert v[bounds[0][1]] == pytest.approx(0.5, abs=0.1)  # grasped: about half of the task
    assert np.corrcoef(np.arange(n), v)[0, 1] > 0.9


def test_lift_levels_end_in_order_and_validate(lift):
    sim, spec, demo, bounds, _ = lift
    lowest, highest = spec.levels[0], spec.levels[-1]
    finals = {}
    for k, level in enumerate([lowest, highest]):
        plan = plan_trajectory(len(demo.states), bounds, level, np.random.default_rng(10 + k))
        r = execute_plan(sim, demo.states, demo.actions, plan, np.random.default_rng(k))
        v = _progress(lift, r)
        finals[level.level] = float(v[-1])
        # recovery states keep unit quaternions for the cube's free joint
        pos = even_positions(len(r), spec.frames)
        truth = GroundTruth(
            progress=[float(v[p]) for p in pos],
            state_type=[r.state_type[p] for p in pos],
            level=level.level,
        )
        ep = Episode(id=f"lift{k}", task="Lift", frame_indices=pos, view_names=["v"], truth=truth)
        assert validate_episode(ep, max_level=highest.level) == []
    assert finals[lowest.level] < 0.2
    assert finals[highest.level] >= 0.95


def test_lift_interpolated_states_keep_unit_quaternions(lift):
    sim, _, demo, _, _ = lift
    model = sim.model
    a, b = demo.states[0].copy(), demo.states[-1]
    jid = next(j for j in range(model.njnt) if model.jnt_type[j] == 0)  # the cube's free joint
    adr = 1 + int(model.jnt_qposadr[jid]) + 3
    a[adr : adr + 4] = [0.0, 0.0, 0.0, 1.0]  # turned 180 degrees about z
    mid = sim.interpolate(a, b, 0.5)
    assert np.linalg.norm(mid[adr : adr + 4]) == pytest.approx(1.0)
    sim.set_state(mid)
    assert np.all(np.isfinite(sim.point("cube")))
