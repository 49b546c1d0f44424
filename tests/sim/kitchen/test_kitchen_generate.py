"""A tiny kitchen dataset: episodes record their scene and wording and look different."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def test_kitchen_episodes_record_scene_and_instruction(tmp_path):
    pytest.importorskip("robosuite")
    from rover.io.dataset import read_episode
    from rover.sim.generate import GenerateConfig, generate
    from rover.sim.tasks import get_task

    name = "kitchen.TurnOnMicrowave"
    cfg = GenerateConfig(
        tasks=[name], per_level=2, levels=["last"], frames=6, size=48, views=["left"], demos=1
    )
    ids = generate(cfg, tmp_path / "ds")
    assert len(ids) == 2
    eps = [read_episode(tmp_path / "ds", i) for i in sorted(ids)]
    spec = get_task(name)
    wordings = [spec.description, *spec.paraphrases]
    scenes = []
    for ep in eps:
        assert ep.task == wordings[ep.extra["instruction"]]
        assert ep.task_group == "appliances"
        scene = ep.extra["scene"]
        assert scene["layout"]["Microwave"] is not None
        assert set(scene["textures"]) == {"floor", "wall", "counter", "wood"}
        scenes.append(scene)
        assert ep.truth.qa[0].answer is True  # the top level presses the button
    # one demonstration: same layout; each episode its own look
    assert scenes[0]["layout"] == scenes[1]["layout"]
    assert scenes[0]["light_seed"] != scenes[1]["light_seed"]
    a, b = (ep.frames("left")[0].astype(int) for ep in eps)
    assert np.abs(a - b).mean() > 5
