"""Pick-and-place levels: the set-down ending and the endings every protocol task gets."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.levels import ENDINGS_BY_KIND, LevelSpec
from rover.sim.perturb import RandomSegment, TrajectoryPlan, execute_plan
from rover.sim.tasks import get_task
from rover.sim.tasks._common import PICK_PLACE_ENDINGS


def test_settle_lowers_in_the_grasp_then_opens_and_stops_the_drift(action_recorder):
    sim = action_recorder(7)
    seg = RandomSegment(q=0, w=20, scale=0.5, hold=1, grip=-1.0, drift=(0, 0, -1.0), settle=8)
    plan = TrajectoryPlan(2, ((0, 1),), (seg,), 4, True)
    execute_plan(sim, np.zeros((2, 3)), np.zeros((1, 7)), plan, np.random.default_rng(0))
    acts = np.stack(sim.actions)
    assert len(acts) == 20
    # the first 8 steps: gripper closed, the hand moved by the drift alone (no noise)
    assert np.all(acts[:8, -1] == 1.0)
    assert np.allclose(acts[:8, :3], [0.0, 0.0, -1.0]) and np.allclose(acts[:8, 3:6], 0.0)
    # then the fingers open and the random part runs without the drift
    assert np.all(acts[8:, -1] == -1.0)
    assert abs(acts[8:, 2].mean()) < 0.3 and acts[8:, :6].std() > 0.1


def test_a_segment_without_settle_keeps_the_drift_throughout(action_recorder):
    sim = action_recorder(7)
    seg = RandomSegment(q=0, w=12, scale=0.1, hold=1, grip=-1.0, drift=(0, 0, 0.3))
    plan = TrajectoryPlan(2, ((0, 1),), (seg,), 3, True)
    execute_plan(sim, np.zeros((2, 3)), np.zeros((1, 7)), plan, np.random.default_rng(0))
    z = np.stack(sim.actions)[:, 2]
    assert np.all(z > 0.15)  # 0.3 drift, at most 0.1 of noise


@pytest.mark.parametrize(
    "task", ["PickPlaceCan", "NutAssemblyRound", "Stack", "Lift", "kitchen.PickPlaceSinkToCounter"]
)
def test_protocol_tasks_end_their_pre_carry_levels_with_the_pick_place_endings(task):
    spec = get_task(task)
    by_kind = {lv.level: lv for lv in spec.levels}
    kinds = [c.partition(":")[0] for c in spec.milestones]
    for level, lv in by_kind.items():
        if lv.completes or level - 1 >= len(kinds) or kinds[level - 1] not in PICK_PLACE_ENDINGS:
            continue
        want = PICK_PLACE_ENDINGS[kinds[level - 1]]
        for field, value in want.items():
            assert getattr(lv, field) == value, (task, level, field)
    # L2 backs the open hand off upwards; L4 (when there is one) sets the object down first
    assert by_kind[2].terminal_grip == "open" and by_kind[2].terminal_drift[2] > 0
    if "carry" in kinds:
        four = by_kind[kinds.index("carry") + 1]
        assert four.terminal_settle[0] > 0 and four.terminal_drift[2] < 0


def test_articulated_tasks_keep_their_own_endings():
    door = {lv.level: lv for lv in get_task("Door").levels}
    assert door[2].terminal_drift == ENDINGS_BY_KIND["contact"].get("terminal_drift", (0, 0, 0))
    assert all(lv.terminal_settle == (0, 0) for lv in door.values())
    LevelSpec(level=4, terminal_settle=(0, 3))  # a valid range
    with pytest.raises(ValueError):
        LevelSpec(level=4, terminal_settle=(3, 1))
