"""Ground-truth validation on rover.episode types (no MuJoCo needed)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rover.episode import Episode, Event, FrameFacts, GroundTruth, ObjectFacts, StateType
from rover.sim.validate import event_problems, validate_dataset, validate_episode


def _episode(progress, level=1, task="t", eid="e", **truth) -> Episode:
    n = len(progress)
    return Episode(
        id=eid,
        task=task,
        frame_indices=list(range(n)),
        view_names=["v"],
        truth=GroundTruth(progress=progress, level=level, **truth),
    )


def test_good_episode_has_no_problems(make_episode):
    ep = make_episode(n=10)
    ep.truth.progress[0] = 0.0
    assert validate_episode(ep, max_level=3) == []


def test_start_must_be_exactly_zero_and_values_in_range():
    assert any("starts at" in p for p in validate_episode(_episode([0.01, 0.5])))
    ep = _episode([0.0, 0.5])
    ep.truth.progress[1] = 1.5  # bypasses the pydantic validator, as a buggy writer would
    assert any("[0, 1]" in p for p in validate_episode(ep))
    ep.truth.progress[1] = float("nan")
    assert any("[0, 1]" in p for p in validate_episode(ep))
    real = _episode([0.3, 0.5], progress_source="frame_number")
    assert validate_episode(real) == []  # only simulated values must start at 0


def test_highest_level_must_nearly_finish():
    assert validate_episode(_episode([0.0, 0.9], level=4), max_level=4)
    assert validate_episode(_episode([0.0, 0.96], level=4), max_level=4) == []
    assert validate_episode(_episode([0.0, 0.5], level=3), max_level=4) == []


def test_state_type_length_and_first_frame():
    ep = _episode([0.0, 0.5])
    ep.truth.state_type = [StateType.expert]
    assert any("state types" in p for p in validate_episode(ep))
    ep.truth.state_type = [StateType.non_expert, StateType.expert]
    assert any("first frame" in p for p in validate_episode(ep))


def test_events_agree_with_facts():
    held = FrameFacts(gripper="closed", holding="can", contacts=["can"])
    free = FrameFacts()
    facts = [free, held, free]
    assert event_problems(Event(name="grasp", object="can", frame=1), facts) == []
    assert event_problems(Event(name="grasp", object="can", frame=0), facts)
    assert event_problems(Event(name="drop", object="can", frame=2), facts) == []
    assert event_problems(Event(name="drop", object="can", frame=1), facts)
    assert event_problems(Event(name="grasp", object="can", frame=None), facts) == []
    assert event_problems(Event(name="grasp", object="can", frame=7), facts)
    lifted = FrameFacts(objects={"can": ObjectFacts(lifted=True)})
    carried = FrameFacts(holding="can", objects={"can": ObjectFacts(lifted=True)})
    assert event_problems(Event(name="pick_up", object="can", frame=0), [carried]) == []
    assert event_problems(Event(name="pick_up", object="can", frame=0), [lifted])  # not held
    # a grasp is a hold beginning; a drop and a place end one
    assert event_problems(Event(name="grasp", object="can", frame=2), [free, held, held])
    assert event_problems(Event(name="drop", object="can", frame=2), [free, free, free])
    placed = FrameFacts(objects={"can": ObjectFacts(inside="bin 2")})
    assert event_problems(Event(name="place", object="can", frame=1), [held, placed]) == []
    assert event_problems(Event(name="place", object="can", frame=0), [placed])  # no hold
    loose = FrameFacts(objects={"can": ObjectFacts()})
    assert event_problems(Event(name="place", object="can", frame=1), [held, loose])
    door = FrameFacts(articulations={"door": 0.4})
    assert event_problems(Event(name="open_start", object="door", frame=0), [door]) == []
    assert event_problems(Event(name="press", object="button", frame=0), [FrameFacts()])


def test_episode_reports_event_fact_mismatch():
    facts = [FrameFacts(), FrameFacts()]
    ep = _episode([0.0, 0.5], facts=facts, events=[Event(name="grasp", object="can", frame=1)])
    assert any("grasp" in p for p in validate_episode(ep))


def test_subtasks_and_qa_bounds():
    from rover.episode import QAItem, Subtask

    ep = _episode(
        [0.0, 0.5, 1.0],
        subtasks=[Subtask(name="a", start=0, end=1), Subtask(name="b", start=1, end=5)],
        qa=[QAItem(question="Did it?", answer=False, frame=1)],
    )
    probs = validate_episode(ep)
    assert any("subtask 'b'" in p for p in probs)
    assert any("answered 'no'" in p for p in probs)


def test_dataset_levels_must_end_in_order():
    good = [
        _episode([0.0, 0.1], level=1, eid="a"),
        _episode([0.0, 0.5], level=2, eid="b"),
        _episode([0.0, 1.0], level=3, eid="c"),
    ]
    assert validate_dataset(good) == []
    bad = [
        _episode([0.0, 0.9], level=1, eid="a"),
        _episode([0.0, 0.5], level=2, eid="b"),
        _episode([0.0, 0.97], level=3, eid="c"),
    ]
    probs = validate_dataset(bad)
    assert any("level 2 ends lower" in p for p in probs)
    top_short = [_episode([0.0, 0.2], level=1, eid="a"), _episode([0.0, 0.8], level=2, eid="b")]
    assert any("b: highest level" in p for p in validate_dataset(top_short))


def test_bundled_dataset_validates():
    bundled = Path(__file__).resolve().parents[2] / "src" / "rover" / "data" / "bundled"
    if not (bundled / "dataset.json").exists():
        pytest.skip("bundled dataset not generated yet")
    from rover.io.dataset import load_dataset

    episodes = load_dataset(bundled, load_frames=False)
    assert episodes
    assert validate_dataset(episodes) == []
