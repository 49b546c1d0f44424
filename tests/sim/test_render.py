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


def test_left_and_right_views_see_gripper_objects_and_goals_of_every_task(sim_env):
    """Projected into the free views aimed by `view_centre`, the gripper, every task object
    and every goal point lie inside the frame at the start of each task."""
    from rover.sim.render import in_view, view_centre
    from rover.sim.tasks import get_task, task_names

    for name in task_names():
        spec = get_task(name)
        sim = sim_env(name)
        sim.reset(0)
        centre = view_centre(sim)
        pts = {"gripper": sim.point("eef")}
        pts.update({o.name: sim.point(o.name) for o in spec.objects})
        pts.update({s.goal: sim.point(s.goal) for s in spec.subtasks if s.goal})
        for view in ("left", "right"):
            for what, p in pts.items():
                assert in_view(view, centre, p), f"{name}: {what} is outside the {view} view"
            assert not in_view(view, centre, centre + [0.0, 0.0, 3.0])  # far overhead: not
