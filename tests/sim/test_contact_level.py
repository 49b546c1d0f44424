"""Articulated levels: a "contact" video ends with the open hand at the part, above every
"approach" video of the same demo, and cuts are drawn where the expert is in the band."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.attempt import within_band


def test_within_band_keeps_the_window_steps_whose_expert_progress_is_in_the_band():
    # the hand covers most of the way early, then creeps: progress by step is not linear
    expert = np.array([0.0, 0.1, 0.2, 0.28, 0.33, 0.36, 0.38, 0.39, 0.40, 0.41])
    assert within_band((2, 9), expert, (0.25, 0.37)) == (3, 5)
    assert within_band((2, 9), expert, (0.0, 1.0)) == (2, 9)
    assert within_band((2, 9), expert, None) == (2, 9)
    # no step of the window in the band: the window as it was (the band check decides)
    assert within_band((2, 4), expert, (0.5, 0.6)) == (2, 4)


def test_articulated_approach_and_contact_levels_meet_at_the_touch_line():
    from rover.sim.cuts import BAND_UNDO, ExpertMarks, progress_band, touch_line
    from rover.sim.tasks import get_task

    spec = get_task("TurnKnob")
    comps = spec.milestones
    m = ExpertMarks(steps=(10, 20, 30, 40), holds={"knob": ((24, 50),)}, length=60)
    expert = np.linspace(0.0, 1.0, 60)
    app, con = expert[10], expert[20]
    levels = {lv.level: lv for lv in spec.levels}
    l2 = progress_band(levels[2], comps, m, expert)
    l3 = progress_band(levels[3], comps, m, expert)
    line = touch_line(app, con)
    assert l2 == pytest.approx((app - BAND_UNDO, line)) and l3 == pytest.approx((line, 1.0))
    # never closer to the contact than BAND_UNDO (the open hand at the part is worth a
    # little less than the expert's closing fingers), and the midpoint when that is lower
    assert line <= con - BAND_UNDO + 1e-12
    assert touch_line(0.2, 0.5) == pytest.approx(0.35)
    assert touch_line(0.38, 0.46) == pytest.approx(0.36)
    # a pick-and-place contact level keeps its own band (the midpoint ceiling for L2)
    pp = get_task("PickPlaceCan")
    pm = ExpertMarks(steps=(10, 20, 30, 33, 60, 80), holds={"can": ((22, 80),)}, length=90)
    pe = np.linspace(0.0, 1.0, 90)
    band = progress_band(pp.levels[1], pp.milestones, pm, pe)
    assert band[1] == pytest.approx((pe[10] + pe[20]) / 2)


def test_a_prefix_that_already_shows_the_next_component_is_replanned():
    from rover.episode import FrameFacts
    from rover.sim.attempt import _prefix_shows_next
    from rover.sim.tasks import get_task

    spec = get_task("Door")
    level3 = next(lv for lv in spec.levels if lv.level == 3)
    door = [0.0, 0.0, 0.06, 0.01, 0.0, 0.0]  # a recovered deviation swings it ajar at 2
    facts = [FrameFacts(articulations={"door": v}) for v in door]
    pos = [0, 10, 20, 30, 40, 50]
    assert _prefix_shows_next(spec, level3, facts, pos, n_prefix=35)
    assert not _prefix_shows_next(spec, level3, facts, pos, n_prefix=15)  # (the ending's)
    top = next(lv for lv in spec.levels if lv.completes)
    assert not _prefix_shows_next(spec, top, facts, pos, n_prefix=35)


@pytest.mark.sim
def test_knob_contact_level_ends_at_the_knob_above_the_approach_level(sim_env):
    pytest.importorskip("robosuite")
    from rover.sim.attempt import demo_marks, make_attempts, trim_demo
    from rover.sim.cuts import progress_band
    from rover.sim.experts import run_expert
    from rover.sim.tasks import get_task

    spec = get_task("TurnKnob")
    sim = sim_env("TurnKnob")
    demo = run_expert(sim, 2)
    assert demo.success
    sim.reset(2)
    sim.begin(demo.states[0])
    states, actions, ends = trim_demo(sim, demo.states, demo.actions, list(demo.subtask_ends))
    demos = [(states, actions, ends, 2)]
    levels = {lv.level: lv for lv in spec.levels}
    marks: dict = {}
    got = {}
    for lv in (2, 3):
        tries = make_attempts(sim, spec, levels[lv], demos, {}, 0, lv * 10_000, 30, marks=marks)
        got[lv] = next((a for a in tries if not a.problems), None)
        assert got[lv] is not None, lv  # some try within MAX_TRIES shows the level
    contact = got[3]
    last = contact.facts[-1]
    events = {e.name: e.frame for e in contact.events}
    assert events["contact"] is not None and events["grasp"] is None
    assert events["turn_start"] is None and last.articulations["knob"] < 0.1
    # the hand stays at the knob (it used to back off 10-30 cm upwards, ending below the
    # approach level) with its fingers open
    assert last.objects["knob"].reach < 0.04 and last.gripper == "open"
    # so the contact video ends above the approach level's ceiling, and above its video
    expert = next(v for k, v in marks.items() if k[0] == "progress")
    mk = demo_marks(sim, spec, states)
    ceiling = progress_band(levels[2], spec.milestones, mk, expert)[1]
    assert contact.progress[-1] >= ceiling > got[2].progress[-1]
