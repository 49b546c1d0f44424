"""A task's own narrowing of the scene draw: the fixture's yaw, and décor kept off a band.

MicrowaveThawing turns the microwave one way only and keeps décor off the hinge side
(`rover.sim.kitchen.thawing`); the draw must honour both on every seed."""

from __future__ import annotations

import numpy as np

from rover.sim.kitchen.objects import DECOR_COUNT, draw_decor
from rover.sim.kitchen.scene import draw_layout


def test_task_yaw_range_narrows_the_fixture_draw() -> None:
    yaws = [
        draw_layout(np.random.default_rng(s), ["Microwave"], {"Microwave": (-0.2, 0.0)})[
            "Microwave"
        ].yaw
        for s in range(40)
    ]
    assert all(-0.2 <= y <= 0.0 for y in yaws)
    assert max(yaws) - min(yaws) > 0.1  # still drawn, not pinned
    wide = [
        draw_layout(np.random.default_rng(s), ["Microwave"])["Microwave"].yaw for s in range(40)
    ]
    assert max(wide) > 0.0  # without the task's range the fixture's own applies


def test_decor_clear_band_leaves_those_spots_empty() -> None:
    for s in range(30):
        kept = draw_decor(np.random.default_rng(s), clear=(-1.2, -0.2))
        assert kept and all(d["y"] > -0.2 for d in kept)
        assert len(draw_decor(np.random.default_rng(s))) == DECOR_COUNT
