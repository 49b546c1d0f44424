"""The level-hand orientation the scripted expert can ask for (`Scripted.pitch`), which
the cabinet, microwave and coffee-machine pick-and-place tasks need (docs/kitchen.md)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rover.sim.experts import Scripted

# robosuite's Panda start pose: approach (z) down, fingers (x) closing along world y
DOWN = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])


def _script(current: np.ndarray) -> Scripted:
    xmat = np.zeros((2, 9))
    xmat[1] = current.ravel()
    script = Scripted(SimpleNamespace(data=SimpleNamespace(site_xmat=xmat), _eef_site=1))
    script.down = DOWN
    return script


@pytest.mark.parametrize("yaw", [0.0, 0.3, -0.2])
def test_pitch_asks_for_a_level_hand_pointing_along_the_yaw(yaw):
    level = Rotation.from_euler("yz", [-np.pi / 2, yaw]).as_matrix() @ DOWN
    approach, fingers = level[:, 2], level[:, 0]  # the eef x axis: the fingers slide along it
    assert np.allclose(approach, [np.cos(yaw), np.sin(yaw), 0.0], atol=1e-9)
    assert abs(fingers[2]) < 1e-9  # the fingers close horizontally
    script = _script(level)
    script.pitch = -np.pi / 2
    assert np.linalg.norm(script.rot_error(yaw)) < 1e-9
    # from the hand pointing down: the quarter turn about world y, then the yaw
    script = _script(DOWN)
    script.pitch = -np.pi / 2
    turn = Rotation.from_euler("yz", [-np.pi / 2, yaw]).as_rotvec()
    assert np.allclose(script.rot_error(yaw), turn, atol=1e-9)
    if yaw == 0.0:
        assert np.allclose(turn, [0.0, -np.pi / 2, 0.0])


def test_without_pitch_the_orientation_is_the_top_down_one():
    """pitch 0 keeps the tabletop experts' yaw-and-tilt target exactly."""
    for yaw, tilt in ((0.4, 0.0), (-0.3, -0.6)):
        want = Rotation.from_euler("zx", [yaw, tilt]).as_matrix() @ DOWN
        script = _script(want)
        script.tilt = tilt
        assert np.linalg.norm(script.rot_error(yaw)) < 1e-9
        assert np.linalg.norm(_script(DOWN).rot_error(yaw)) == pytest.approx(abs(yaw), abs=1e-6)
