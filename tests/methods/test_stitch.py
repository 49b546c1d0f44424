"""Stitching subtask progress into one full-task curve (hand-computed trees)."""

from __future__ import annotations

import pytest

from rover.methods.stitch import Point, StitchLine, fill_forward, stitch


def test_two_subtasks_map_to_halves():
    a = StitchLine(0, [Point(1, 50), Point(2, 100)])
    b = StitchLine(2, [Point(3, 20), Point(4, 100)])
    curve, _ = stitch(StitchLine(0, [a, b]), 5)
    # subtask i of n contributes 100*i/n + p/n
    assert curve == pytest.approx([0, 25, 50, 60, 100])


def test_nesting_composes():
    a1 = StitchLine(0, [Point(1, 100)])
    a2 = StitchLine(1, [Point(2, 50), Point(3, 100)])
    a = StitchLine(0, [a1, a2])
    b = StitchLine(3, [Point(4, 40)])
    c = StitchLine(4, [Point(5, 100)])
    curve, sources = stitch(StitchLine(0, [a, b, c]), 7)
    third = 100 / 3
    # a covers 0..33.3 split in halves; b 33.3..66.7; c 66.7..100; frame 6 filled forward
    assert curve == pytest.approx(
        [0, third / 2, third * 0.75, third, third + 0.4 * third, 100, 100]
    )
    assert sources[2].line is a2 and sources[2].raw == 50


def test_planned_subtasks_set_n():
    a = StitchLine(0, [Point(1, 50), Point(2, 100)])
    root = StitchLine(0, [a], planned=4)
    curve, _ = stitch(root, 4)
    assert curve == pytest.approx([0, 12.5, 25, 25])


def test_anchor_only_where_nothing_predicted():
    # b starts at 2 (0% of b = 50 overall) but 2 was predicted by a at 90% -> 45
    a = StitchLine(0, [Point(1, 50), Point(2, 90)])
    b = StitchLine(2, [Point(4, 50)])
    curve, _ = stitch(StitchLine(0, [a, b]), 5)
    assert curve == pytest.approx([0, 25, 45, 45, 75])
    # an unpredicted anchor frame takes the child's 0%
    b2 = StitchLine(3, [Point(4, 50)])
    curve2, _ = stitch(StitchLine(0, [a, b2]), 5)
    assert curve2 == pytest.approx([0, 25, 45, 50, 75])


def test_own_points_of_a_decomposed_line_and_clamping():
    a = StitchLine(0, [Point(1, -150), Point(2, 250)])
    root = StitchLine(0, [Point(1, 10), a])
    curve, _ = stitch(root, 4)
    # root's own 10 at frame 1 is overwritten by a later child point (-100 clamped -> 0)
    assert curve == pytest.approx([0, 0, 100, 100])


def test_frame_zero_is_zero_and_gaps_fill_forward():
    root = StitchLine(0, [Point(0, 40), Point(3, 60), Point(5, 20)])
    curve, _ = stitch(root, 8)
    assert curve == [0, 0, 0, 60, 60, 20, 20, 20]
    assert fill_forward([None, 5, None, None, 7, None]) == [0, 5, 5, 5, 7, 7]
    assert fill_forward([9, None]) == [0, 0]
    assert fill_forward([]) == []
