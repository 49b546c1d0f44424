"""Levels by milestone: expert marks, cut windows, and endings that keep the gripper."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.sim.audit import facts_changed
from rover.sim.cuts import (
    CARRY_WINDOW_FRAMES,
    ExpertMarks,
    cut_window,
    draw_cut,
    expert_marks,
    held_contact_window,
)
from rover.sim.levels import ENDINGS_BY_KIND, LevelSpec, by_milestone, component_kind
from rover.sim.perturb import (
    ExpertSegment,
    RandomSegment,
    TrajectoryPlan,
    execute_plan,
    plan_trajectory,
)
from rover.sim.tasks import get_task

COMPS = [f"{k}:can" for k in ("approach", "contact", "pick_up", "carry", "approach_goal", "place")]


def _facts(n: int = 40) -> list[FrameFacts]:
    """A scripted pick-and-place of "can", one fact per expert step: the hand closes in
    from 30 cm (approach at step 6), touches at 10, holds from 14, lifts at 16, comes
    over the bin at 24 and lets go at 30, the can then resting in bin 4."""
    out = []
    for t in range(n):
        reach = max(0.3 - 0.035 * t, 0.01)
        held = 14 <= t < 30
        lifted = 16 <= t < 30
        out.append(
            FrameFacts(
                gripper="closed" if held else "open",
                contacts=["can"] if 10 <= t < 31 else [],
                holding="can" if held else None,
                objects={
                    "can": ObjectFacts(
                        position=(0.0, 0.0, 0.9),
                        lifted=lifted,
                        reach=reach,
                        goal_distance=max(0.3 - 0.012 * max(t - 16, 0), 0.0) if t < 30 else 0.0,
                        inside="bin 4" if t >= 30 else None,
                    )
                },
            )
        )
    return out


@pytest.fixture(scope="module")
def marks() -> ExpertMarks:
    spec = get_task("PickPlaceCan")
    assert spec.milestones == COMPS
    return expert_marks(spec, _facts())


def test_expert_marks_find_each_component_first_step(marks):
    # approach: within 10 cm and half way (reach <= 0.1 first at t=6); contact at 10;
    # pick-up = held and lifted (16); carry = 4 held-lifted steps (19); over the bin (8 cm)
    # only at t = 35, after the release, so never while held (None); place at the release
    assert marks.steps[:4] == (6, 10, 16, 19)
    assert marks.steps[5] == 30
    assert marks.holds["can"] == ((14, 30),)
    assert marks.length == 40


def test_a_hold_that_starts_with_the_contact_is_cut_at_the_contact(marks):
    """Both fingers closing on the object at the very step of the first touch leave no
    touched-not-held stretch: L3 is then cut at that step (and only L3)."""
    from dataclasses import replace

    levels = {lv.level: lv for lv in get_task("PickPlaceCan").levels}
    assert held_contact_window(levels[3], COMPS, marks) is None  # the hold starts at 14 > 10
    square = replace(marks, steps=(6, 14, 16, 19, 24, 30))  # contact and hold both at 14
    assert cut_window(levels[3], COMPS, square, 30) is None
    assert held_contact_window(levels[3], COMPS, square) == (14, 14)
    assert all(held_contact_window(levels[k], COMPS, square) is None for k in (1, 2, 4, 5, 6, 7))


def test_cut_window_per_kind(marks):
    levels = {lv.level: lv for lv in get_task("PickPlaceCan").levels}
    # L1: before the approach; L2: approached, before contact
    assert cut_window(levels[1], COMPS, marks, 30) == (0, 5)
    assert cut_window(levels[2], COMPS, marks, 30) == (6, 9)
    # L3: contact, and before the hold begins (not merely before the lift)
    assert cut_window(levels[3], COMPS, marks, 30) == (10, 13)
    # L4: within CARRY_WINDOW_FRAMES video frames of the pick-up (frames, not the four
    # expert steps the carry takes at step rate: 6 frames space them widely)
    lo, hi = cut_window(levels[4], COMPS, marks, 6)
    w = sum(levels[4].terminal_w) / 2
    span = CARRY_WINDOW_FRAMES / 5
    assert (lo, hi) == (16, int((16 + span * w) / (1 - span)))
    assert hi > marks.steps[3]
    assert cut_window(levels[4], COMPS, marks, 200)[1] < hi  # denser frames: sooner
    # L5 needs approach_goal, which this demo never shows: the stretch runs to the end
    assert cut_window(levels[5], COMPS, marks, 30) == (19, 39)
    # L6 needs a component the demo never shows: no window (the level falls back)
    assert cut_window(levels[6], COMPS, marks, 30) is None
    assert cut_window(levels[7], COMPS, marks, 30) is None  # the top level never cuts


def test_place_window_ends_before_the_release():
    m = ExpertMarks(steps=(2, 4, 8, 10, 20, 31), holds={"can": ((6, 30),)}, length=40)
    lv = next(lv for lv in get_task("PickPlaceCan").levels if lv.level == 6)
    assert cut_window(lv, COMPS, m, 30) == (20, 29)


def test_contact_level_skips_a_demo_whose_hold_starts_with_the_contact():
    """No step of such a demo is touched-not-held: cutting at the contact cut into the
    hold (a grasp and a drop in a "contact" video); another demo is used instead."""
    m = ExpertMarks(steps=(2, 6, 9, 12, 20, 31), holds={"can": ((6, 30),)}, length=40)
    lv = next(lv for lv in get_task("PickPlaceCan").levels if lv.level == 3)
    assert cut_window(lv, COMPS, m, 30) is None
    later = ExpertMarks(steps=(2, 6, 9, 12, 20, 31), holds={"can": ((8, 30),)}, length=40)
    assert cut_window(lv, COMPS, later, 30) == (6, 7)


def test_snap_position_puts_a_frame_on_the_cut():
    from rover.sim.attempt import snap_position

    pos = [0, 10, 20, 30, 40]
    assert snap_position(pos, 23) == [0, 10, 23, 30, 40]
    assert snap_position(pos, 20) == pos
    assert snap_position(pos, 2) == [0, 2, 20, 30, 40]
    assert snap_position(pos, 40) == pos and snap_position([0, 5], 3) == [0, 5]


def test_draw_cut_stays_in_the_window_fraction():
    lv = LevelSpec(level=2, terminate_subtask=0, milestone_cut=(0.25, 0.75))
    rng = np.random.default_rng(0)
    cuts = [draw_cut((100, 200), lv, rng) for _ in range(200)]
    assert 125 <= min(cuts) and max(cuts) <= 175 and len(set(cuts)) > 20


def test_by_milestone_sets_endings_by_kind_and_keeps_fallbacks():
    base = get_task("Door").levels
    kinds = [component_kind(c) for c in get_task("Door").milestones]
    assert kinds == ["approach", "contact", "start", "finish"]
    for lv in base:
        if lv.completes:
            assert lv.milestone_cut is None
            continue
        want = ENDINGS_BY_KIND[kinds[lv.level - 1]]
        assert lv.milestone_cut == want["milestone_cut"]
        assert lv.terminal_grip == want["terminal_grip"]
        assert lv.terminate_subtask is not None  # the subtask-fraction fallback stays
    again = by_milestone(base, get_task("Door").milestones)
    assert [lv.model_dump() for lv in again] == [lv.model_dump() for lv in base]
    with pytest.raises(ValueError):
        LevelSpec(level=1, milestone_cut=(0.6, 0.4))


def test_plan_leaves_the_expert_at_the_given_cut():
    lv = LevelSpec(level=3, terminate_subtask=0, terminate_at=(0.0, 0.1), deviations=(0, 0))
    plan = plan_trajectory(100, [(0, 49), (50, 99)], lv, np.random.default_rng(1), cut=73)
    assert isinstance(plan.segments[-1], RandomSegment) and plan.segments[-1].q == 73
    assert plan.segments[-2] == ExpertSegment(0, 73)


@pytest.mark.parametrize("grip", [-1.0, 1.0, None])
def test_terminal_grip_holds_the_gripper_channel(action_recorder, grip):
    sim = action_recorder(4)
    seg = RandomSegment(q=0, w=30, scale=1.0, hold=1, grip=grip)
    plan = TrajectoryPlan(2, ((0, 1),), (seg,), 1, True)
    execute_plan(sim, np.zeros((2, 3)), np.zeros((1, 4)), plan, np.random.default_rng(0))
    g = np.array([a[-1] for a in sim.actions])
    if grip is None:
        assert g.min() < -0.5 and g.max() > 0.5  # random, as in the paper
    else:
        assert np.all(g == grip)
    arm = np.array([a[:3] for a in sim.actions])
    assert arm.std() > 0.2  # the arm still moves at random


def test_facts_changed_is_the_audit_motion_test():
    a = FrameFacts(eef=(0.0, 0.0, 1.0), gripper_opening=0.5, articulations={"knob": 0.1})
    assert not facts_changed(a, a.model_copy(update={"eef": (0.004, 0.0, 1.0)}))
    assert facts_changed(a, a.model_copy(update={"eef": (0.006, 0.0, 1.0)}))
    assert facts_changed(a, a.model_copy(update={"gripper_opening": 0.53}))
    assert facts_changed(a, a.model_copy(update={"articulations": {"knob": 0.13}}))


def test_progress_bands_rise_with_the_level():
    from rover.sim.cuts import BAND_GAP, BAND_UNDO, progress_band

    spec = get_task("PickPlaceCan")
    m = ExpertMarks(steps=(10, 20, 30, 33, 60, 80), holds={"can": ((22, 80),)}, length=90)
    expert = np.linspace(0.0, 1.0, 90)  # progress per expert step
    p = {c: expert[t] for c, t in zip(COMPS, m.steps, strict=True)}
    bands = {lv.level: progress_band(lv, COMPS, m, expert) for lv in spec.levels}
    app, con = p["approach:can"], p["contact:can"]
    assert bands[1] == (0.0, 1.0) and bands[7] is None
    assert bands[2] == pytest.approx((app - BAND_UNDO, (app + con) / 2))
    # touched, the open hand backing off: from under the approach up to the contact
    assert bands[3] == pytest.approx((app - BAND_UNDO / 2, con))
    # set back down, the open hand at it: above the approach-contact midpoint, not carried
    assert bands[4] == pytest.approx(((app + con) / 2, p["pick_up:can"] - BAND_GAP))
    assert bands[5] == pytest.approx((p["carry:can"] - BAND_UNDO, 1.0))
    # floors and ceilings rise with the level (the pick-and-place endings order the
    # levels' final states; the bands only keep each one near where it belongs)
    for lo_lv, hi_lv in ((2, 3), (3, 4), (4, 5)):
        assert bands[lo_lv][0] < bands[hi_lv][0]
        assert bands[lo_lv][1] <= bands[hi_lv][1]
    gone = ExpertMarks(steps=(10, None, None, None, None, None), holds={}, length=90)
    assert progress_band(spec.levels[2], COMPS, gone, expert) is None


def test_window_starts_once_every_earlier_component_is_shown():
    # a Stack-like demo grasps the cube already over its target (approach_goal at 26,
    # before carry at 36): "approach placing" starts at 36, "carry" has no stretch
    m = ExpertMarks(steps=(11, 26, 33, 36, 26, 81), holds={"can": ((26, 80),)}, length=90)
    levels = {lv.level: lv for lv in get_task("PickPlaceCan").levels}
    assert cut_window(levels[6], COMPS, m, 30) == (36, 79)
    assert cut_window(levels[5], COMPS, m, 30) is None


def test_a_pick_up_after_a_placement_is_a_general_band():
    """Restock L3 ("placed the milk, not yet picked up the can") ends anywhere above the
    placement less BAND_UNDO, not under a touched-not-held ceiling meant for contacts."""
    from rover.sim.cuts import BAND_UNDO, progress_band

    spec = get_task("Restock")
    comps = spec.milestones
    m = ExpertMarks(steps=(20, 40, 60, 80), holds={"milk": ((15, 40),)}, length=90)
    expert = np.linspace(0.0, 1.0, 90)
    level3 = next(lv for lv in spec.levels if lv.level == 3)
    assert progress_band(level3, comps, m, expert) == pytest.approx((expert[40] - BAND_UNDO, 1.0))
