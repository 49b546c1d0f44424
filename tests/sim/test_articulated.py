"""Articulated fixtures (drawer, button, knob): specs, determinism, scripted experts,
articulation facts and events, and a tiny end-to-end generation run."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.tasks import get_task, task_names

ARTICULATED = ["OpenDrawer", "PressButton", "TurnKnob", "CloseDrawer"]
PART = {
    "OpenDrawer": "drawer",
    "CloseDrawer": "drawer",
    "PressButton": "button",
    "TurnKnob": "knob",
}
# (event that starts the motion or None, event that completes it)
EVENTS = {
    "OpenDrawer": ("open_start", "open_finish"),
    "CloseDrawer": ("close_start", "close_finish"),
    "PressButton": (None, "press"),
    "TurnKnob": ("turn_start", "turn_finish"),
}


def test_articulated_tasks_are_registered_in_their_groups():
    names = task_names()
    groups = {n: get_task(n).group for n in ARTICULATED}
    assert all(n in names for n in ARTICULATED)
    assert groups == {
        "OpenDrawer": "drawers",
        "CloseDrawer": "drawers",
        "PressButton": "buttons",
        "TurnKnob": "knobs",
    }
    assert [len(get_task(n).levels) for n in ARTICULATED] == [5, 3, 5, 5]  # Table 5 rows


def test_robosuite_make_finds_the_fixture_envs():
    pytest.importorskip("robosuite")
    from rover.sim.env import make_robosuite_env

    env = make_robosuite_env("RoverKnob")
    env.reset()
    assert env.part == "knob" and env.progress() == 0.0 and not env._check_success()


@pytest.mark.sim
@pytest.mark.parametrize("name", ARTICULATED)
def test_reset_is_deterministic_for_a_seed(name, sim_env):
    sim = sim_env(name)
    a = sim.reset(5)
    where_a = sim.point(PART[name]).copy()
    sim.reset(6)
    where_b = sim.point(PART[name]).copy()
    c = sim.reset(5)
    np.testing.assert_array_equal(a, c)
    np.testing.assert_array_equal(sim.point(PART[name]), where_a)
    assert not np.allclose(where_a, where_b)  # the seed places the fixture


@pytest.mark.sim
@pytest.mark.parametrize("name", ARTICULATED)
def test_expert_moves_the_part_and_events_match_facts(name, sim_env):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states, qa_items

    spec = get_task(name)
    sim = sim_env(name)
    demo = run_expert(sim, 3)
    assert demo.success and len(demo.subtask_ends) == len(spec.subtasks)
    again = run_expert(sim, 3)
    np.testing.assert_array_equal(demo.states, again.states)

    part = PART[name]
    facts = facts_for_states(sim, demo.states)
    first, last = facts[0].articulations[part], facts[-1].articulations[part]
    if name == "CloseDrawer":
        assert first == 1.0 and last <= 0.1  # starts open, ends closed
    else:
        assert first == 0.0 and last >= 0.9
    assert (part in facts[-1].pressed) == (name == "PressButton")
    assert part not in facts[0].pressed

    events = {e.name: e.frame for e in detect_events(spec, facts) if e.object == part}
    start, finish = EVENTS[name]
    t = events[finish]
    assert t is not None and events["contact"] is not None
    # the event's frame is the first one whose facts show it
    value = [f.articulations[part] for f in facts]
    if name == "CloseDrawer":
        assert value[t] <= 0.1 and all(v > 0.1 for v in value[:t])
    elif name == "PressButton":
        assert part in facts[t].pressed and all(part not in f.pressed for f in facts[:t])
        assert events["turn_on"] == t
        lamp = []
        for state in demo.states[[0, -1]]:
            sim.set_state(state)
            lamp.append(sim._named_xpos("Button_lamp")[2])
        assert lamp[1] - lamp[0] > 0.02  # the "on" lamp rose out of the case
    else:
        assert value[t] >= 0.9 and all(v < 0.9 for v in value[:t])
    if start is not None:
        assert events[start] is not None and events[start] <= t
    qa = {q.template: q for q in qa_items(spec, detect_events(spec, facts))}
    assert all(q.answer for q in qa.values()), qa


@pytest.mark.sim
def test_drawer_goal_is_the_open_handle(sim_env):
    from rover.sim.experts import run_expert

    sim = sim_env("OpenDrawer")
    sim.reset(0)
    goal = sim.point("goal:drawer_open")
    handle = sim.point("drawer:handle")
    # the goal lies OPEN_Q along the slide, towards the robot (-x), at handle height
    assert np.linalg.norm(goal - handle) == pytest.approx(0.12, abs=1e-6)
    assert goal[0] < handle[0] and goal[2] == pytest.approx(handle[2], abs=1e-6)
    demo = run_expert(sim, 0)
    sim.set_state(demo.states[-1])
    assert np.linalg.norm(sim.point("drawer:handle") - goal) < 0.02


@pytest.mark.sim
@pytest.mark.slow
def test_generate_tiny_drawer_dataset_validates(tmp_path):
    pytest.importorskip("robosuite")
    from typer.testing import CliRunner

    from rover.cli import app
    from rover.io.dataset import load_dataset
    from rover.sim.validate import validate_dataset

    out = tmp_path / "ds"
    args = ["generate", "--tasks", "OpenDrawer", "--per-level", "1", "--levels", "1,last"]
    args += ["--frames", "8", "--size", "48", "--views", "left", "--demos", "1"]
    res = CliRunner().invoke(app, [*args, "--out", str(out)])
    assert res.exit_code == 0, res.output
    eps = load_dataset(out)
    assert [e.id for e in eps] == ["OpenDrawer-L1-000", "OpenDrawer-L5-000"]
    assert validate_dataset(eps) == []
    top = eps[1].truth
    assert top.facts[-1].articulations["drawer"] >= 0.9 and top.progress[-1] >= 0.95
    assert {q.template for q in top.qa} == {
        "did_contact",
        "did_grasp",
        "did_open_start",
        "did_open_finish",
    }
