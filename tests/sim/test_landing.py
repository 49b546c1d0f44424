"""A release a few centimetres above the goal is a place where the object lands.

On hand-written facts (no MuJoCo): the expert opens its fingers a little above the bin, so
at the frame the hold ends the can is still falling (in no region, or passing the table's
height); the event rules, the audit's check of them and its top-level check must agree.
"""

from __future__ import annotations

import pytest

from rover.episode import Episode, FrameFacts, GroundTruth, ObjectFacts
from rover.sim.facts import detect_events
from rover.sim.tasks import get_task
from rover.sim.validate import LANDING_FRAMES, event_problems, validate_episode


def _f(held: bool = False, inside: str | None = None, on: str | None = None) -> FrameFacts:
    can = ObjectFacts(position=(0.0, 0.0, 0.9), lifted=held, inside=inside, on=on)
    return FrameFacts(holding="can" if held else None, contacts=["can"] if held else [],
                      objects={"can": can})  # fmt: skip


def _released(falling: int) -> list[FrameFacts]:
    """Held for 5 frames, let go, `falling` frames in the air, then in bin 4 (its goal)."""
    return (
        [_f(on="table")] + [_f(held=True)] * 5 + [_f(on="table")] + [_f()] * (falling - 1)
        + [_f(inside="bin 4")] * 3
    )  # fmt: skip


def _ends(facts: list[FrameFacts]) -> dict[str, int | None]:
    events = detect_events(get_task("PickPlaceCan"), facts)
    return {e.name: e.frame for e in events if e.name in ("drop", "place")}


@pytest.mark.parametrize("falling", [0, 1, LANDING_FRAMES])
def test_a_can_landing_in_its_bin_soon_after_the_release_is_placed(falling):
    facts = _released(falling) if falling else [_f()] + [_f(held=True)] * 5 + [_f(inside="bin 4")]
    ends = _ends(facts)
    assert ends["drop"] is None
    assert ends["place"] == 6 + falling  # the frame it lands, not the frame it left the hand
    for e in detect_events(get_task("PickPlaceCan"), facts):
        assert event_problems(e, facts) == [], e


def test_a_can_that_falls_longer_than_the_landing_frames_was_dropped():
    ends = _ends(_released(LANDING_FRAMES + 1))
    assert ends == {"drop": 6, "place": None}


def test_a_regrasp_before_it_lands_keeps_the_first_release_a_drop():
    facts = [_f()] + [_f(held=True)] * 3 + [_f()] + [_f(held=True)] * 3 + [_f(inside="bin 4")]
    ends = _ends(facts)
    assert ends["drop"] == 4 and ends["place"] == 8


def test_the_audit_flags_a_drop_in_a_top_level_video():
    facts = _released(LANDING_FRAMES + 1)
    n = len(facts)
    events = detect_events(get_task("PickPlaceCan"), facts)
    truth = GroundTruth(progress=[0.0] + [1.0] * (n - 1), level=7, facts=facts, events=events)
    ep = Episode(
        id="PickPlaceCan-L7-000", task="Pick up the can.", frame_indices=list(range(n)),
        view_names=["left"], truth=truth,
    )  # fmt: skip
    assert any("shows a drop of 'can' at frame 6" in p for p in validate_episode(ep, max_level=7))
    assert not any("shows a drop" in p for p in validate_episode(ep, max_level=8))
