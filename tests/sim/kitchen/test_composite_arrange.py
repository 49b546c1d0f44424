"""Kitchen composite ArrangeVegetables: its spec, the board region, two items in MuJoCo."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.sim.kitchen.utensils import BOARD_HALF, BOARD_REGION
from rover.sim.milestones import level_problems
from rover.sim.tasks import get_task

TASK = "kitchen.ArrangeVegetables"
ITEMS = ("first vegetable", "second vegetable")


def test_spec_has_table5_levels_app_n_subtasks_and_c3_questions():
    spec = get_task(TASK)
    assert spec.frames == 60 and spec.group == "arrange_vegetables"
    assert [s.name for s in spec.subtasks] == [
        "pick up the first vegetable",
        "place the first vegetable on the cutting board",
        "pick up the second vegetable",
        "place the second vegetable on the cutting board",
    ]
    assert [s.end_signal for s in spec.subtasks[1::2]] == [f"placed:{o}" for o in ITEMS]
    assert [lv.name for lv in spec.levels] == [
        "Fail to pick up the first vegetable",
        "Pick up the first vegetable and place it on the cutting board",
        "Pick up the second vegetable and place it on the cutting board",
    ]
    assert spec.milestones == [f"place:{o}" for o in ITEMS]
    assert spec.levels[-1].completes and not spec.levels[0].completes
    # level 1 leaves before the first grasp with the fingers open: it never picks up
    assert spec.levels[0].terminal_grip == "open" and spec.levels[0].milestone_cut[1] <= 0.3
    assert [(q.event, q.object) for q in spec.qa_templates] == [
        (e, o) for o in ITEMS for e in ("pick_up", "drop", "place")
    ]
    assert len(spec.paraphrases) == 3
    # the two goal spots on the board are distinct points
    assert len({g.body for g in spec.goals.values()}) == 2


def _f(first=None, second=None, held=None) -> FrameFacts:
    return FrameFacts(
        holding=held,
        objects={
            "first vegetable": ObjectFacts(on=first),
            "second vegetable": ObjectFacts(on=second),
        },
    )


def test_levels_are_components_every_earlier_one_achieved():
    spec = get_task(TASK)
    start = _f("counter", "counter")
    first_on = [start, _f(None, "counter", held="first vegetable"), _f("cutting board", "counter")]
    both_on = [*first_on, _f("cutting board", None, "second vegetable")]
    both_on.append(_f("cutting board", "cutting board"))
    assert level_problems(1, spec.milestones, [start, start], []) == []
    assert level_problems(1, spec.milestones, first_on, [])  # shows the component it fails
    assert level_problems(2, spec.milestones, first_on, []) == []
    assert level_problems(2, spec.milestones, both_on, [])
    assert level_problems(3, spec.milestones, both_on, []) == []
    assert level_problems(3, spec.milestones, first_on, [])


def test_board_region_takes_items_resting_on_the_top_face_only():
    top = BOARD_REGION.top
    assert BOARD_REGION.holds(np.array([0.02, -0.05, 0.03]), top)  # resting on it
    assert BOARD_REGION.holds(np.array([0.0, 0.0, 0.06]), top + 0.03)  # let go 3 cm above
    assert not BOARD_REGION.holds(np.array([0.0, 0.0, 0.2]), top + 0.15)  # carried over it
    assert not BOARD_REGION.holds(np.array([BOARD_HALF[0] + 0.01, 0.0, 0.03]), top)  # off it
    assert not BOARD_REGION.holds(np.array([0.0, 0.0, 0.0]), -BOARD_HALF[2])  # counter level


@pytest.fixture(scope="module")
def arrange(sim_env):
    return sim_env(TASK)


@pytest.mark.sim
def test_two_different_instances_start_on_the_counter_and_rest(arrange):
    env = arrange.env
    pairs = set()
    for seed in range(6):
        arrange.reset(seed)
        objs = env.scene.to_json()["objects"]
        names = [o["name"] for o in objs]
        assert len(set(names)) == 2, names  # two different vegetables
        pairs.add(tuple(names))
        assert env.scene.to_json()["board"] is not None
        for role in ITEMS:
            assert env.object_place(role) == ("on", "counter"), (seed, role)
        start = {r: arrange.point(r) for r in ITEMS}
        hold = np.zeros(len(arrange.action_low))
        for _ in range(10):
            arrange.step(hold)
        for r in ITEMS:
            assert np.linalg.norm(arrange.point(r) - start[r]) < 0.005
    assert len(pairs) >= 3
    arrange.reset(3)
    first = env.scene.to_json()
    arrange.reset(3)
    assert env.scene.to_json() == first


@pytest.mark.sim
def test_chained_expert_puts_both_on_the_board_and_events_say_place(arrange):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    demo = run_expert(arrange, 1)
    assert demo.success and len(demo.subtask_ends) == 4
    picks = np.linspace(0, len(demo.states) - 1, 60).round().astype(int)
    facts = facts_for_states(arrange, demo.states[picks], demo.states[np.maximum(picks - 1, 0)])
    for role in ITEMS:
        assert facts[0].objects[role].on == "counter"
        assert facts[-1].objects[role].on == "cutting board"
    events = {(e.name, e.object): e.frame for e in detect_events(arrange.spec, facts)}
    first, second = ITEMS
    assert events[("drop", first)] is None and events[("drop", second)] is None
    assert events[("pick_up", first)] < events[("place", first)] < events[("pick_up", second)]
    assert events[("pick_up", second)] < events[("place", second)]
