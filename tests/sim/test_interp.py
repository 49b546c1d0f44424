"""State interpolation for recoveries: slerp and joint-aware interpolate_state."""

from __future__ import annotations

import numpy as np
import pytest

from rover.sim.interp import interpolate_state, slerp

mujoco = pytest.importorskip("mujoco")

# a free body (7 qpos, 6 qvel), a hinge (1, 1), a ball joint (4, 3): nq = 12, nv = 10
MJCF = """
<mujoco>
  <worldbody>
    <body name="box" pos="0 0 1">
      <freejoint name="free"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
    </body>
    <body name="arm" pos="1 0 0">
      <joint name="hinge" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
      <body name="wrist" pos="0.5 0 0">
        <joint name="ball" type="ball"/>
        <geom type="sphere" size="0.05"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _quat_z(angle: float) -> np.ndarray:
    return np.array([np.cos(angle / 2), 0.0, 0.0, np.sin(angle / 2)])


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(MJCF)


def _state(model, t, pos, quat, hinge, ball, vel) -> np.ndarray:
    qpos = np.concatenate([pos, quat, [hinge], ball])
    assert qpos.shape == (model.nq,)
    return np.concatenate([[t], qpos, np.full(model.nv, vel)])


def test_slerp_endpoints_and_midpoint():
    q0, q1 = _quat_z(0.0), _quat_z(np.pi / 2)
    np.testing.assert_allclose(slerp(q0, q1, 0.0), q0, atol=1e-12)
    np.testing.assert_allclose(slerp(q0, q1, 1.0), q1, atol=1e-12)
    # halfway between 0 and 90 degrees about z is 45 degrees about z
    np.testing.assert_allclose(slerp(q0, q1, 0.5), _quat_z(np.pi / 4), atol=1e-12)


def test_slerp_takes_short_path_and_normalises():
    q0 = _quat_z(0.0)
    q1 = -_quat_z(np.pi / 2)  # same rotation as +q1; the long way round would pass 225 deg
    mid = slerp(2.0 * q0, 3.0 * q1, 0.5)  # unnormalised inputs
    assert np.linalg.norm(mid) == pytest.approx(1.0)
    np.testing.assert_allclose(mid, _quat_z(np.pi / 4), atol=1e-12)


def test_slerp_nearly_equal_quaternions_is_stable():
    q0, q1 = _quat_z(0.0), _quat_z(1e-9)
    out = slerp(q0, q1, 0.3)
    assert np.all(np.isfinite(out))
    assert np.linalg.norm(out) == pytest.approx(1.0)


def test_slerp_rejects_zero_quaternion():
    with pytest.raises(ValueError):
        slerp(np.zeros(4), _quat_z(0.1), 0.5)


def test_interpolate_state_joint_by_joint(model):
    a = _state(model, 0.0, [0, 0, 1], _quat_z(0.0), 0.0, _quat_z(0.0), 0.0)
    b = _state(model, 2.0, [2, 4, 1], _quat_z(np.pi / 2), 1.0, _quat_z(np.pi), 4.0)
    mid = interpolate_state(model, a, b, 0.5)
    assert mid[0] == pytest.approx(1.0)  # time linear
    np.testing.assert_allclose(mid[1:4], [1, 2, 1])  # free-joint position linear
    np.testing.assert_allclose(mid[4:8], _quat_z(np.pi / 4), atol=1e-12)  # free quat slerp
    assert mid[8] == pytest.approx(0.5)  # hinge linear
    np.testing.assert_allclose(mid[9:13], _quat_z(np.pi / 2), atol=1e-12)  # ball quat slerp
    np.testing.assert_allclose(mid[13:], 2.0)  # velocities linear
    # a naive linear blend would leave the quaternion unnormalised
    assert np.linalg.norm(0.5 * a[4:8] + 0.5 * b[4:8]) < 0.99
    assert np.linalg.norm(mid[4:8]) == pytest.approx(1.0)


def test_interpolate_state_endpoints_and_mujoco_accepts_it(model):
    a = _state(model, 0.0, [0, 0, 1], _quat_z(0.3), 0.2, _quat_z(-0.4), 0.1)
    b = _state(model, 1.0, [1, 0, 2], _quat_z(2.0), -0.5, _quat_z(1.0), -0.3)
    np.testing.assert_allclose(interpolate_state(model, a, b, 0.0), a, atol=1e-12)
    np.testing.assert_allclose(interpolate_state(model, a, b, 1.0), b, atol=1e-12)
    data = mujoco.MjData(model)
    s = interpolate_state(model, a, b, 0.25)
    data.qpos[:] = s[1 : 1 + model.nq]
    data.qvel[:] = s[1 + model.nq :]
    mujoco.mj_forward(model, data)
    assert np.all(np.isfinite(data.xpos))
    np.testing.assert_allclose(data.xpos[model.body("box").id], [0.25, 0, 1.25])


def test_interpolate_state_rejects_wrong_layout(model):
    a = np.zeros(1 + model.nq + model.nv)
    with pytest.raises(ValueError, match="nq"):
        interpolate_state(model, a, a[:-1], 0.5)
    with pytest.raises(ValueError, match="nq"):
        interpolate_state(model, a[:5], a[:5], 0.5)
