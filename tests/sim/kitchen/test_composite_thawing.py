"""Kitchen composite MicrowaveThawing: two worked parts of one fixture (door, button).

The spec comes from `rover.sim.kitchen.thawing.microwave_thawing` (registered as
kitchen.MicrowaveThawing). The MuJoCo tests check that the door's and the button's facts,
predicates, goals and joint fractions each come from their own joint, that the scene is
drawn from the task's own part of the microwave's ranges, and that the chained expert
does the four components in order and leaves the door shut."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.sim.facts import detect_events
from rover.sim.milestones import level_problems

DOOR, FOOD = "microwave door", "food item"


def thawing():
    import rover.sim.tasks  # noqa: F401  (the registry first: see test_composite_presoak)
    from rover.sim.kitchen.thawing import microwave_thawing

    return microwave_thawing()


def test_spec_has_table5_levels_subtasks_and_c3_questions():
    spec = thawing()
    assert spec.frames == 60 and spec.group == "microwave_thawing"
    assert [(s.name, s.end_signal, s.joint) for s in spec.subtasks] == [
        ("reach the microwave door's handle", f"touched:{DOOR}", None),
        ("open the microwave door", f"door_opened:{DOOR}", f"joint:{DOOR}"),
        ("pick up the food item", f"lifted:{FOOD}", None),
        ("place the food item in the microwave", f"placed:{FOOD}", None),
        ("close the microwave door", f"door_closed:{DOOR}", "joint:microwave door closed"),
        ("press the microwave's start button", "pressed:button", "joint:button"),
    ]
    assert [lv.name for lv in spec.levels] == [
        "Fail to open the microwave door",
        "Open the microwave door",
        "Pick up the food item and place it in the microwave",
        "Close the microwave door",
        "Press the microwave start button",
    ]
    assert spec.levels[-1].completes and not any(lv.completes for lv in spec.levels[:-1])
    assert spec.milestones == [
        f"open_finish:{DOOR}",
        f"place:{FOOD}",
        f"close_finish:{DOOR}",
        "press:button",
    ]
    assert [q.text for q in spec.qa_templates] == [
        "Did the robot open the microwave? If so, when?",
        "Did the robot pick up the food item? If so, when?",
        "Did the robot drop the food item? If so, when?",
        "Did the robot place the food item in the microwave? If so, when?",
    ]
    assert len(spec.paraphrases) == 3
    keys = [p["key"] for p in spec.env_kwargs["parts"]]
    assert keys == [DOOR, "microwave door closed", "button"]
    # every joint point a subtask follows names a worked part
    assert {s.joint[6:] for s in spec.subtasks if s.joint} == set(keys)


def _f(door=0.0, pressed=False, food=None, held=None) -> FrameFacts:
    inside = "microwave" if food == "microwave" else None
    return FrameFacts(
        holding=held,
        objects={
            FOOD: ObjectFacts(inside=inside, on=food if food == "counter" else None),
            DOOR: ObjectFacts(),
            "button": ObjectFacts(),
        },
        articulations={DOOR: door, "button": 1.0 if pressed else 0.0},
        pressed=["button"] if pressed else [],
    )


def _video(stop: int) -> list[FrameFacts]:
    """The components in order, the video stopping before component `stop` (5: all)."""
    frames = [_f(food="counter"), _f(0.5, food="counter"), _f(0.95, food="counter")]
    if stop > 2:
        frames += [_f(1.0, food=None, held=FOOD), _f(1.0, food="microwave")]
    if stop > 3:
        frames += [_f(0.6, food="microwave"), _f(0.05, food="microwave")]
    if stop > 4:
        frames += [_f(0.0, pressed=True, food="microwave")]
    return frames


def test_door_events_open_then_close_and_each_level_shows_its_components():
    spec = thawing()
    facts = _video(5)
    found = {(e.name, e.object): e.frame for e in detect_events(spec, facts)}
    # the door starts closed: closing is read only after it was open (frames 5, 6)
    assert found[("open_start", DOOR)] == 1 and found[("open_finish", DOOR)] == 2
    assert found[("close_start", DOOR)] == 5 and found[("close_finish", DOOR)] == 6
    assert found[("press", "button")] == 7 and found[("turn_on", "button")] == 7
    assert found[("place", FOOD)] == 4 and found[("drop", FOOD)] is None
    for level in range(1, 6):
        video = _video(level) if level > 1 else [_f(food="counter"), _f(0.5, food="counter")]
        events = detect_events(spec, video)
        assert level_problems(level, spec.milestones, video, events) == [], level
    # a door never opened has no close events, though it stands closed throughout
    shut = [_f(food="counter")] * 3
    found = {(e.name, e.object): e.frame for e in detect_events(spec, shut)}
    assert found[("close_start", DOOR)] is None and found[("close_finish", DOOR)] is None


@pytest.fixture(scope="module")
def sim():
    pytest.importorskip("robosuite")
    from rover.sim.env import SimEnv

    return SimEnv(thawing())


def _set(sim, part: str, q: float) -> None:
    env = sim.env
    _, jid, addr = env._part_joints[part]
    sim.data.qpos[addr] = q
    env.sim.forward()


@pytest.mark.sim
def test_door_and_button_facts_predicates_and_goals_come_from_their_own_joints(sim):
    from rover.sim.facts import frame_facts
    from rover.sim.kitchen.thawing import DOOR_OPEN

    env = sim.env
    sim.reset(0)
    assert frame_facts(sim).articulations == {DOOR: 0.0, "button": 0.0}
    assert env.object_place(FOOD) == ("on", "counter")
    # shut at the start is not "closed the door": that needs the food inside
    assert not sim.predicate(f"door_closed:{DOOR}")
    assert not sim.predicate(f"door_opened:{DOOR}") and not sim.predicate("pressed:button")
    handle_at_open = sim.point("goal:door_swung")
    top_pressed = sim.point("goal:button_pressed")
    _set(sim, "door", DOOR_OPEN)
    f = frame_facts(sim)
    assert f.articulations == {DOOR: 1.0, "button": 0.0} and f.pressed == []
    assert sim.predicate(f"door_opened:{DOOR}") and not sim.predicate("pressed:button")
    assert np.allclose(sim.point(f"{DOOR}:handle"), handle_at_open, atol=1e-6)
    assert sim.point(f"joint:{DOOR}")[0] == pytest.approx(1.0)
    assert sim.point("joint:microwave door closed")[0] == pytest.approx(0.0)
    assert sim.point("joint:button")[0] == pytest.approx(0.0)
    # the button pressed: its own fact and signal; the door's stay as they were
    _set(sim, "button", -0.012)
    f = frame_facts(sim)
    assert f.articulations == {DOOR: 1.0, "button": 1.0} and f.pressed == ["button"]
    assert sim.predicate("pressed:button") and sim.predicate(f"door_opened:{DOOR}")
    assert np.allclose(sim.point("button:top"), top_pressed, atol=2e-3)
    # the food in the cavity and the door shut again: closed, and the task done
    a, _ = env.role_qpos[FOOD]
    sim.data.qpos[a : a + 3] = sim.point("goal:microwave") + [0.0, 0.0, 0.04]
    _set(sim, "door", 0.0)
    hold = np.zeros(len(sim.action_low))
    for _ in range(20):
        sim.step(hold)
    assert env.object_place(FOOD) == ("inside", "microwave")
    assert sim.predicate(f"door_closed:{DOOR}") and not sim.predicate(f"door_opened:{DOOR}")
    assert sim.point("joint:microwave door closed")[0] == pytest.approx(1.0)
    # after the working() switches, the env's joint is the first part's again
    assert env.part == DOOR and env.kind == "door" and env.target == pytest.approx(DOOR_OPEN)


@pytest.mark.sim
def test_scene_draws_the_microwave_from_the_tasks_own_ranges(sim):
    from rover.sim.kitchen.thawing import MICROWAVE_X, MICROWAVE_Y, MICROWAVE_YAW

    seen = []
    for seed in range(4):
        sim.reset(seed)
        place = sim.env.scene.layout["Microwave"]
        assert MICROWAVE_X[0] <= place.x <= MICROWAVE_X[1]
        assert MICROWAVE_Y[0] <= place.y <= MICROWAVE_Y[1]
        assert MICROWAVE_YAW[0] <= place.yaw <= MICROWAVE_YAW[1]
        assert all(d["y"] > -0.2 for d in sim.env.scene.decor)  # none on the hinge side
        seen.append((place.x, place.y, place.yaw))
    assert len(set(seen)) == 4  # still drawn per seed


@pytest.mark.sim
@pytest.mark.slow
def test_chained_expert_thaws_in_order_and_leaves_the_door_shut(sim):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    demo = run_expert(sim, 0)  # seed 0 once hit a décor pot's handle picking the food
    assert demo.success and len(demo.subtask_ends) == 6
    assert demo.subtask_ends == sorted(demo.subtask_ends)
    picks = np.linspace(0, len(demo.states) - 1, 60).round().astype(int)
    facts = facts_for_states(sim, demo.states[picks], demo.states[np.maximum(picks - 1, 0)])
    last = facts[-1]
    assert last.objects[FOOD].inside == "microwave"
    assert last.articulations[DOOR] <= 0.1  # shut again, not pulled ajar leaving it
    assert last.pressed == ["button"] or last.articulations["button"] >= 0.9
    ev = {(e.name, e.object): e.frame for e in detect_events(sim.spec, facts)}
    order = [
        ev[("open_finish", DOOR)],
        ev[("place", FOOD)],
        ev[("close_finish", DOOR)],
        ev[("press", "button")],
    ]
    assert None not in order and order == sorted(order), order
    assert ev[("drop", FOOD)] is None
