"""Rendering: right size, upright (floor below the walls), and views differ."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from rover.errors import InputError

pytestmark = pytest.mark.sim


def test_views_have_the_right_size_and_are_upright(sim_env):
    from rover.sim.render import StateRenderer

    sim = sim_env("Lift")
    state = sim.reset(0)
    r = StateRenderer(sim.model, 64, 48)
    frames = r.render(np.stack([state, state]), ["left", "right", "wrist"])
    for v, arr in frames.items():
        assert arr.shape == (2, 48, 64, 3) and arr.dtype == np.uint8, v
        assert arr.std() > 5, f"{v} view is blank"
    assert not np.array_equal(frames["left"], frames["right"])
    # upright: in a third-person view the floor lies below the arena walls
    r.renderer.enable_segmentation_rendering()
    r.set_state(state)
    floor = int(mujoco.mj_name2id(sim.model, mujoco.mjtObj.mjOBJ_GEOM, "floor"))
    walls = [g for g in range(sim.model.ngeom) if sim.model.geom(g).name.startswith("wall")]
    for view in ("left", "right"):
        r.renderer.update_scene(r.data, camera=r.camera(view), scene_option=r.option)
        seg = r.renderer.render()[..., 0]
        rows = np.arange(seg.shape[0])[:, None].repeat(seg.shape[1], 1)
        assert (seg == floor).any() and np.isin(seg, walls).any()
        assert rows[seg == floor].mean() > rows[np.isin(seg, walls)].mean(), view
    r.renderer.disable_segmentation_rendering()
    r.close()


def test_unknown_view_lists_valid_ones():
    from rover.sim.render import check_views

    with pytest.raises(InputError, match="valid views: wrist, left, right"):
        check_views(["left", "top"])
