"""Trajectory levels (App. B, Table 5): default ladders, validation, seeding."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from rover.sim.levels import LevelSpec, default_levels, level_schedule, plan_seed


def test_default_levels_match_table_5_pick_and_place_count():
    levels = default_levels([["Approach", "Contact"], ["Keep grasp", "Approach placing"]])
    assert [lv.level for lv in levels] == list(range(1, 8))  # Table 5: seven levels
    assert levels[0].terminate_subtask == 0 and levels[0].terminate_at[1] <= 0.1
    # cuts inside subtask 0 at 1/3 and 2/3, then "pick up" = the start of subtask 1
    assert [lv.terminate_subtask for lv in levels] == [0, 0, 0, 1, 1, 1, None]
    assert levels[1].terminate_at == pytest.approx((1 / 3 - 0.1, 1 / 3 + 0.1))
    assert levels[3].terminate_at == (0.0, 0.05)
    assert levels[-1].completes and not levels[-2].completes


def test_default_levels_without_milestones():
    levels = default_levels([[], []])  # composite tasks: one level per finished subtask
    assert len(levels) == 3
    assert [lv.terminate_subtask for lv in levels] == [0, 1, None]


def test_terminate_points_rise_with_level():
    levels = default_levels([["a"], ["b", "c"]])
    keys = [
        (lv.terminate_subtask, lv.terminate_at[0])
        for lv in levels
        if lv.terminate_subtask is not None
    ]
    assert keys == sorted(keys)


@pytest.mark.parametrize(
    "bad",
    [
        {"w": (5, 2)},
        {"h": (0, 3)},
        {"n_interp": (0, 2)},
        {"terminate_at": (0.2, 1.5)},
        {"scale": (-0.1, 0.5)},
        {"hold": (0, 2)},
        {"nested_prob": 1.5},
    ],
)
def test_level_spec_rejects_bad_ranges(bad):
    with pytest.raises(ValidationError):
        LevelSpec(level=1, **bad)


def test_plan_seed_is_stable_and_distinct():
    a = plan_seed(0, "Lift", 3).integers(0, 1 << 30, 4)
    b = plan_seed(0, "Lift", 3).integers(0, 1 << 30, 4)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, plan_seed(0, "Door", 3).integers(0, 1 << 30, 4))
    assert not np.array_equal(a, plan_seed(1, "Lift", 3).integers(0, 1 << 30, 4))
    # CRC32 of the task name, not Python's per-process hash(): fixed known value
    assert plan_seed(0, "Lift", 0).integers(0, 1000) == plan_seed(0, "Lift", 0).integers(0, 1000)


def test_level_schedule_counts_and_indices_independent_of_other_levels():
    levels = default_levels([["a"], []])
    sched = level_schedule(levels, 2)
    assert [lv.level for _, lv in sched] == [1, 1, 2, 2, 3, 3, 4, 4]
    more = dict((lv.level, i) for i, lv in level_schedule(levels, 5)[::5])
    assert more[3] == dict((lv.level, i) for i, lv in sched[::2])[3]  # same first index
    with pytest.raises(ValueError):
        level_schedule(levels, -1)
