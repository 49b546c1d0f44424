"""Stitching subtask progress into one full-task curve (Sec. 5.1, hand-computed trees).

A subtask's values are divided by n and added to the full-task value at the previous
subtask's last frame; nested lines compose.
"""

from __future__ import annotations

import pytest

from rover.methods.stitch import Point, StitchLine, fill_forward, stitch


def test_two_completed_subtasks_map_to_halves():
    a = StitchLine(0, [Point(1, 50), Point(2, 100)])
    b = StitchLine(2, [Point(3, 20), Point(4, 100)])
    curve, _ = stitch(StitchLine(0, [a, b], planned=2), 5)
    assert curve == pytest.approx([0, 25, 50, 60, 100])


def test_early_stop_in_subtask_one_of_two_scores_half():
    # the video ends at 70% of subtask 1 of a two-subtask plan: 70 / 2 = 35
    a = StitchLine(0, [Point(1, 30), Point(2, 70)])
    curve, _ = stitch(StitchLine(0, [a], planned=2), 3)
    assert curve == pytest.approx([0, 15, 35])


def test_next_subtask_starts_where_the_previous_ended():
    # subtask 1 ended at 90% (45 overall), so subtask 2 starts at 45: 45 + p / 2
    a = StitchLine(0, [Point(1, 50), Point(2, 90)])
    b = StitchLine(2, [Point(3, 20), Point(4, 100)])
    curve, _ = stitch(StitchLine(0, [a, b], planned=2), 5)
    assert curve == pytest.approx([0, 25, 45, 55, 95])


def test_nesting_composes_from_the_previous_end():
    a1 = StitchLine(0, [Point(1, 80)])  # 80% of A1 = 20 overall (A spans 50, A1 25)
    a2 = StitchLine(1, [Point(2, 50), Point(3, 100)])  # from 20: 32.5, 45
    a = StitchLine(0, [a1, a2], planned=2)
    b = StitchLine(3, [Point(4, 40), Point(5, 100)])  # from 45: 65, 95
    curve, sources = stitch(StitchLine(0, [a, b], planned=2), 7)
    assert curve == pytest.approx([0, 20, 32.5, 45, 65, 95, 95])
    assert sources[2].line is a2 and sources[2].raw == 50


def test_n_grows_when_the_model_adds_subtasks():
    a = StitchLine(0, [Point(1, 100)])
    b = StitchLine(1, [Point(2, 50)])
    c = StitchLine(2, [Point(3, 100)])
    # a plan of 2, then a third subtask: n = 3
    curve, _ = stitch(StitchLine(0, [a, b, c], planned=2), 4)
    third = 100 / 3
    assert curve == pytest.approx([0, third, third * 1.5, third * 2.5])
    # no plan at all: n is the number of subtasks the line ended up with
    curve, _ = stitch(StitchLine(0, [StitchLine(0, [Point(1, 60)])]), 2)
    assert curve == pytest.approx([0, 60])


def test_anchor_only_where_nothing_predicted():
    a = StitchLine(0, [Point(1, 50), Point(2, 90)])
    b = StitchLine(3, [Point(4, 50)])  # b's first frame 3 was never answered: its 0% (45)
    curve, _ = stitch(StitchLine(0, [a, b], planned=2), 5)
    assert curve == pytest.approx([0, 25, 45, 45, 70])


def test_negative_and_over_100_values_are_kept():
    a = StitchLine(0, [Point(1, -20), Point(2, 130)])
    root = StitchLine(0, [Point(1, 10), a], planned=2)
    curve, _ = stitch(root, 4)
    # the child's later point overwrites root's own 10; values are halved, not clipped
    assert curve == pytest.approx([0, -10, 65, 65])


def test_frame_zero_is_zero_and_gaps_fill_forward():
    root = StitchLine(0, [Point(0, 40), Point(3, 60), Point(5, 20)])
    curve, _ = stitch(root, 8)
    assert curve == [0, 0, 0, 60, 60, 20, 20, 20]
    assert fill_forward([None, 5, None, None, 7, None]) == [0, 5, 5, 5, 7, 7]
    assert fill_forward([9, None]) == [0, 0]
    assert fill_forward([]) == []
