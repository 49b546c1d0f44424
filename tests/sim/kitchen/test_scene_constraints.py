"""A task's own narrowing of the scene draw: the fixture's x, y and yaw, and décor kept off a
band.

MicrowaveThawing stands the microwave far out, turns it one way only and keeps décor off
the hinge side (`rover.sim.kitchen.thawing`); the draw must honour all three on every
seed, and leave every other random number of the scene as the seed drew it."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.kitchen.fixtures import FIXTURES, narrow_fixture
from rover.sim.kitchen.objects import DECOR_COUNT, draw_decor
from rover.sim.kitchen.scene import draw_layout, draw_scene


def _narrowed() -> dict:
    return {"Microwave": narrow_fixture("Microwave", x_range=(0.095, 0.12), yaw_range=(-0.2, 0.0))}


def test_task_ranges_narrow_the_fixture_draw() -> None:
    places = [
        draw_layout(np.random.default_rng(s), ["Microwave"], _narrowed())["Microwave"]
        for s in range(40)
    ]
    assert all(-0.2 <= p.yaw <= 0.0 for p in places)
    assert all(0.095 <= p.x <= 0.12 for p in places)
    assert max(p.yaw for p in places) - min(p.yaw for p in places) > 0.1  # drawn, not pinned
    assert max(p.x for p in places) - min(p.x for p in places) > 0.01
    wide = [draw_layout(np.random.default_rng(s), ["Microwave"])["Microwave"] for s in range(40)]
    assert max(p.yaw for p in wide) > 0.0  # without the task's range the fixture's own applies
    assert min(p.x for p in wide) < 0.095
    along = {"Microwave": narrow_fixture("Microwave", y_range=(-0.18, -0.07))}
    ys = [
        draw_layout(np.random.default_rng(s), ["Microwave"], along)["Microwave"].y
        for s in range(40)
    ]
    assert all(-0.18 <= y <= -0.07 for y in ys) and max(ys) - min(ys) > 0.05
    assert max(p.y for p in wide) > -0.07


def test_narrowing_keeps_the_rest_of_the_scene() -> None:
    for s in range(10):
        own = draw_scene(np.random.default_rng(s), ["Microwave"], [])
        narrow = draw_scene(np.random.default_rng(s), ["Microwave"], [], _narrowed())
        assert narrow.layout["Microwave"].y == own.layout["Microwave"].y
        assert narrow.textures == own.textures and narrow.light_seed == own.light_seed
        assert narrow.layout["Sink"] == own.layout["Sink"]


def test_a_range_outside_the_fixtures_own_is_refused() -> None:
    lo, hi = FIXTURES["Microwave"].x_range
    with pytest.raises(ValueError, match="Microwave x range"):
        narrow_fixture("Microwave", x_range=(lo - 0.05, hi))
    with pytest.raises(ValueError, match="Microwave yaw range"):
        narrow_fixture("Microwave", yaw_range=(0.1, 0.0))


def test_decor_clear_band_leaves_those_spots_empty() -> None:
    for s in range(30):
        kept = draw_decor(np.random.default_rng(s), clear=(-1.2, -0.2))
        assert kept and all(d["y"] > -0.2 for d in kept)
        assert len(draw_decor(np.random.default_rng(s))) == DECOR_COUNT


def test_a_decor_pots_handles_count_in_its_clearance() -> None:
    """Seed 0 of MicrowaveThawing: a steel pot 33 cm from the food, its handle 13 cm
    from it, stopped the hand picking the food; a small piece as far off stays."""
    from rover.sim.kitchen.composite_env import POT_HANDLE_REACH, clear_decor, decor_overhang
    from rover.sim.kitchen.objects import CATALOGUE

    pot = next(i for i in CATALOGUE if i.name == "steel pan")
    jar = next(i for i in CATALOGUE if i.name == "spice jar")
    assert decor_overhang(pot) == pytest.approx(pot.size[0] + POT_HANDLE_REACH)
    assert decor_overhang(jar) == 0.0  # the gap was set for the small pieces
    food = [{"name": "noodle cup", "qpos": [-0.054, 0.202, 0.84, 1.0, 0.0, 0.0, 0.0]}]
    decor = [
        {"name": pot.name, "x": -0.28, "y": 0.45},
        {"name": jar.name, "x": -0.18, "y": 0.55},
    ]
    assert [d["name"] for d in clear_decor(decor, food)] == [jar.name]
    far = [{**decor[0], "y": 0.8}]  # the same pot further along the counter stays
    assert clear_decor(far, food) == far
