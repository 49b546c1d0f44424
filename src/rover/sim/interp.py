"""Interpolating MuJoCo states for recovery segments (paper Sec. 4.1).

The paper writes recovery as ``s = (1 - alpha) s_dev + alpha s_expert``. Applied literally
to a flat MuJoCo state that averages quaternion components, which leaves unnormalised
orientations (MuJoCo renormalises them, so objects visibly jump). We therefore interpolate
joint by joint: free-joint positions, hinge and slide joints and all velocities linearly,
free-joint and ball-joint orientations by shortest-path slerp.
"""

from __future__ import annotations

import mujoco
import numpy as np

_DOT_LINEAR = 0.9995  # above this cosine slerp is numerically a lerp


def slerp(q0: np.ndarray, q1: np.ndarray, t: float) -> np.ndarray:
    """Spherical linear interpolation between two quaternions along the shortest arc.

    Works for any component order (MuJoCo uses ``w, x, y, z``). Inputs need not be
    normalised; the result always is, so it can be written straight into ``qpos``.

    Args:
        q0: (4,) start quaternion (returned, normalised, at ``t == 0``).
        q1: (4,) end quaternion (returned, possibly sign-flipped, at ``t == 1``).
        t: fraction of the way from ``q0`` to ``q1``.

    Returns:
        (4,) unit quaternion.
    """
    a = np.asarray(q0, dtype=np.float64)
    b = np.asarray(q1, dtype=np.float64)
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0.0 or nb == 0.0:
        raise ValueError("slerp needs non-zero quaternions")
    a, b = a / na, b / nb
    dot = float(np.dot(a, b))
    if dot < 0.0:  # q and -q are the same rotation: take the short way round
        b, dot = -b, -dot
    if dot > _DOT_LINEAR:
        out = a + t * (b - a)
        return out / np.linalg.norm(out)
    theta = np.arccos(min(dot, 1.0))
    s = np.sin(theta)
    out = (np.sin((1.0 - t) * theta) / s) * a + (np.sin(t * theta) / s) * b
    return out / np.linalg.norm(out)


def interpolate_state(
    model: mujoco.MjModel, a: np.ndarray, b: np.ndarray, alpha: float
) -> np.ndarray:
    """Flat robosuite state a fraction ``alpha`` of the way from ``a`` to ``b``.

    Args:
        model: the model both states belong to (gives joint types and qpos addresses).
        a: flat state ``[time, qpos (nq), qvel (nv), ...]`` at ``alpha == 0``.
        b: flat state of the same layout at ``alpha == 1``.
        alpha: interpolation fraction, usually ``z / n_interp`` in ``(0, 1]``.

    Returns:
        A new flat state; trailing entries after qvel (activations), time and velocities
        are linear, orientations slerped.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    need = 1 + model.nq + model.nv
    if a.shape != b.shape or a.ndim != 1 or a.shape[0] < need:
        raise ValueError(
            f"states must be flat arrays of equal length >= 1 + nq + nv = {need}, "
            f"got {a.shape} and {b.shape}"
        )
    out = (1.0 - alpha) * a + alpha * b
    for j in range(model.njnt):
        jt = int(model.jnt_type[j])
        adr = 1 + int(model.jnt_qposadr[j])
        if jt == mujoco.mjtJoint.mjJNT_FREE:
            quat = slice(adr + 3, adr + 7)
        elif jt == mujoco.mjtJoint.mjJNT_BALL:
            quat = slice(adr, adr + 4)
        else:
            continue
        out[quat] = slerp(a[quat], b[quat], alpha)
    return out
