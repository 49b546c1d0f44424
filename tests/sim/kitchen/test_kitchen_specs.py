"""Kitchen suite without MuJoCo: scene draws, paraphrases and the task registry."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rover.errors import InputError
from rover.sim.kitchen.fixtures import FIXTURES, SLOTS
from rover.sim.kitchen.objects import CATALOGUE, CATEGORIES, draw_decor, instances
from rover.sim.kitchen.scene import TEXTURES, draw_scene
from rover.sim.tasks import get_task, task_names


def _scene(seed: int, used=("Microwave",)):
    rng = np.random.default_rng(seed)
    return draw_scene(rng, list(used), draw_decor(rng))


def test_same_seed_same_scene_other_seed_other_scene():
    a, b = _scene(3).to_json(), _scene(3).to_json()
    assert a == b
    others = [_scene(s).to_json() for s in range(4, 10)]
    assert all(o != a for o in others)
    # every part of the scene varies over seeds, not just one of them
    for key in ("layout", "textures", "light_seed", "camera_seed", "decor"):
        assert len({json.dumps(o[key], sort_keys=True) for o in others}) > 1, key
    json.dumps(a)  # recorded in episode.json as is


def test_used_fixture_in_reach_others_in_far_slots_without_overlap():
    for seed in range(30):
        sc = _scene(seed, used=("Stove", "Sink"))
        placed = {n: p for n, p in sc.layout.items() if p is not None}
        stove = sc.layout["Stove"]
        lo, hi = FIXTURES["Stove"].x_range
        assert lo <= stove.x <= hi
        for name, p in placed.items():
            if name not in ("Stove", "Sink"):
                assert p.y in SLOTS
        spans = sorted(
            (p.y - FIXTURES[n].half_width, p.y + FIXTURES[n].half_width) for n, p in placed.items()
        )
        for (_, end), (start, _) in zip(spans, spans[1:], strict=False):
            assert start >= end, f"seed {seed}: fixtures overlap along the counter"


def test_textures_are_robosuite_files():
    pytest.importorskip("robosuite")
    from rover.sim.kitchen.env import TEXTURE_DIR

    for names in TEXTURES.values():
        for name in names:
            assert (TEXTURE_DIR / f"{name}.png").is_file(), name


def test_catalogue_has_several_distinct_instances_per_category():
    for cat in ("mug", "pan", "sponge", "food", "vegetable", "pantry"):
        assert len(instances(cat)) >= 2, cat
    assert len(instances("vegetable")) >= 3
    assert len({i.name for i in CATALOGUE}) == len(CATALOGUE)
    with pytest.raises(KeyError, match="categories"):
        instances("spaceship")
    decor = draw_decor(np.random.default_rng(0))
    assert len({d["category"] for d in decor}) == len(decor)
    assert {d["category"] for d in decor} <= set(CATEGORIES)


def test_kitchen_suite_registered_beside_tabletop():
    kitchen = task_names("kitchen")
    assert "kitchen.OpenDrawer" in kitchen and "OpenDrawer" in task_names()
    assert not set(kitchen) & set(task_names())  # tabletop default unchanged
    assert set(task_names("all")) == set(kitchen) | set(task_names())
    for name in kitchen:
        spec = get_task(name)
        assert spec.suite == "kitchen"
        assert spec.env_name in ("RoverKitchen", "RoverKitchenComposite")
        atomic = ("pick_and_place", "doors_drawers", "appliances", "fixtures_knobs")
        composite = ("microwave_thawing", "restock_pantry", "arrange_vegetables")
        composite += ("prepare_coffee", "presoak_pan")
        assert spec.group in (atomic if spec.frames == 30 else composite)
        assert len(spec.paraphrases) >= 2
    with pytest.raises(InputError, match="valid suites"):
        task_names("garden")
    with pytest.raises(InputError, match="kitchen.TurnOnStove"):
        get_task("TurnOnStoveTop")


def test_paraphrase_is_picked_by_seed_and_subtasks_stay_fixed():
    spec = get_task("kitchen.TurnOnStove")
    picks = [spec.instruction(s) for s in range(40)]
    assert picks == [spec.instruction(s) for s in range(40)]
    wordings = [spec.description, *spec.paraphrases]
    assert {text for _, text in picks} == set(wordings)  # every wording gets used
    assert all(wordings[k] == text for k, text in picks)
    assert get_task("Lift").instruction(5) == (0, get_task("Lift").description)
