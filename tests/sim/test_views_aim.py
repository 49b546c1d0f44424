"""Free views aimed so that nothing but the robot hides the gripper or the task."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


def _renderer(sim):
    from rover.sim.render import StateRenderer

    return StateRenderer(sim.model, 32)


def test_door_right_view_swings_round_until_the_panel_no_longer_hides_the_hand(sim_env):
    from rover.sim.render import FREE_VIEWS, FreeView, view_centre

    sim = sim_env("Door")
    sim.reset(0)
    centre, state = view_centre(sim), sim.get_state()
    r = _renderer(sim)
    try:
        r.set_state(state)
        default = FREE_VIEWS["right"]
        default = FreeView(tuple(centre), default.distance, default.azimuth, default.elevation)
        grip = sim.point("eef")
        assert not r._seen(default, grip)  # robosuite's door panel is in the way
        aims = r.aim_views(state[None], centre)
        r.set_state(state)
        assert aims["right"].azimuth != default.azimuth
        assert r._seen(aims["right"], grip)
        assert aims["left"].azimuth == -default.azimuth  # the left view was clear already
    finally:
        r.close()


def test_aimed_views_see_gripper_objects_and_goals_of_every_task(sim_env):
    """At each task's start, the aimed left and right views keep the gripper, every task
    object and every goal point in frame, and see the gripper unhidden."""
    from rover.sim.render import in_view, view_centre
    from rover.sim.tasks import get_task, task_names

    for name in task_names():
        spec = get_task(name)
        sim = sim_env(name)
        sim.reset(0)
        centre, state = view_centre(sim), sim.get_state()
        r = _renderer(sim)
        try:
            aims = r.aim_views(np.stack([state, state]), centre)
            r.set_state(state)
            pts = {"gripper": sim.point("eef")}
            pts.update({o.name: sim.point(o.name) for o in spec.objects})
            pts.update({s.goal: sim.point(s.goal) for s in spec.subtasks if s.goal})
            for view in ("left", "right"):
                aim = aims[view]
                assert r._seen(aim, pts["gripper"]), f"{name}: gripper hidden in {view}"
                for what, p in pts.items():
                    assert in_view(view, centre, p, aim=aim), f"{name}: {what} not in {view}"
                # the left view stays on the robot's left (+y), the right on its right
                side = np.sign(
                    centre[1]
                    - (
                        aim.lookat[1]
                        - aim.distance
                        * np.sin(np.radians(aim.azimuth))
                        * np.cos(np.radians(aim.elevation))
                    )
                )
                assert side == (-1 if view == "left" else 1), (name, view, aim)
        finally:
            r.close()
