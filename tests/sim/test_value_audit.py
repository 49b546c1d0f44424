"""The audit's articulated-progress check: progress must rise while a part moves."""

from __future__ import annotations

from rover.episode import FrameFacts
from rover.sim.audit import joint_lags


def _facts(values, part="knob"):
    return [FrameFacts(articulations={part: v}) for v in values]


def test_progress_rising_with_the_knob_passes_and_a_jump_at_release_fails():
    turn = [0.0, 0.0, 0.1, 0.4, 0.7, 0.95, 0.95, 0.95]
    follows = [0.0, 0.3, 0.5, 0.65, 0.8, 0.97, 1.0, 1.0]
    assert joint_lags(_facts(turn), follows) == []
    # flat while the knob turns, 1.0 only once the hand lets go (the old TurnKnob curve)
    jumps = [0.0, 0.3, 0.5, 0.5, 0.5, 0.51, 1.0, 1.0]
    (why,) = joint_lags(_facts(turn), jumps)
    assert "knob" in why and "frames 2-5" in why


def test_a_closing_drawer_is_measured_toward_closed_and_unfinished_moves_are_skipped():
    closing = [1.0, 1.0, 0.8, 0.5, 0.2, 0.05]
    assert joint_lags(_facts(closing, "drawer"), [0, 0.5, 0.6, 0.7, 0.85, 1.0]) == []
    assert joint_lags(_facts(closing, "drawer"), [0, 0.5, 0.5, 0.5, 0.5, 0.55])
    # never reaches the goal (a "start opening" level): nothing to check
    assert joint_lags(_facts([0.0, 0.2, 0.5, 0.6]), [0.0, 0.1, 0.1, 0.1]) == []
    # no articulated part, or progress of another length: nothing to check
    assert joint_lags([FrameFacts()] * 3, [0.0, 0.0, 0.0]) == []
    assert joint_lags(_facts([0.0, 1.0]), [0.0]) == []


def test_a_button_clicking_between_two_frames_is_not_a_lag():
    """PressButton's expert: the finger comes down (progress 0.82), the button clicks
    fully in between frames 27 and 28; a two-frame press is still checked."""
    click = [0.0] * 28 + [1.0, 1.0]
    progress = [t / 33 for t in range(28)] + [1.0, 1.0]
    assert joint_lags(_facts(click, "button"), progress) == []
    two = [0.0] * 27 + [0.5, 1.0, 1.0]
    assert joint_lags(_facts(two, "button"), progress)


def test_the_gain_asked_scales_with_the_turns_share_of_a_longer_task():
    """The lever's turn is the last of six subtasks in PreSoakPan: progress follows it
    from 0.85 to 1.0 (its whole share is about 1/6), which is no lag there, but would
    be one in an atomic two-subtask task, whose turn carries half the progress."""
    turn = [0.0, 0.0, 0.08, 0.34, 0.6, 0.85, 0.95, 0.95]
    late = [0.8, 0.83, 0.85, 0.89, 0.94, 0.98, 1.0, 1.0]
    assert joint_lags(_facts(turn, "sink handle"), late, subtasks=6) == []
    (why,) = joint_lags(_facts(turn, "sink handle"), late)
    assert "< 0.25" in why
    # progress flat while the lever turns, rising only after (at the release) stays a
    # lag however many subtasks the task has
    flat = [0.8, 0.83, 0.83, 0.83, 0.83, 0.835, 0.84, 1.0]
    (why,) = joint_lags(_facts(turn, "sink handle"), flat, subtasks=6)
    assert "< 0.08" in why
