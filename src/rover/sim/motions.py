"""Waypoint motions the scripted experts are built from (pick, carry, place).

A `Phase` names a target for the end effector (a function of the current state, so a
script reacts to where objects really are), a gripper command and when it is done
(target reached, a step budget, or both); a `Retry` repeats a group of phases until a
check holds (a missed grasp). The per-object tables say how each object is grasped.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rover.sim.env import SimEnv

OPEN, CLOSE = -1.0, 1.0


@dataclass
class Phase:
    """One leg of a script: move the end effector to `target()` with the gripper set."""

    target: Callable[[], np.ndarray]
    grip: float
    tol: float | None = 0.01  # done when within tol (m); None: run `steps` steps
    steps: int = 60  # step budget (or exact count when tol is None)
    min_steps: int = 0
    yaw: Callable[[], float] | None = None  # grasp yaw about world z (rad), None: keep
    gain: float = 1.0
    track_yaw: bool = False  # re-evaluate `yaw` every step (turning with a door)
    done: Callable[[], bool] | None = None  # extra completion test
    # the hand's pitch from here on (rad about world y, as `Scripted.pitch`; None: keep):
    # a script that points the hand level into the microwave turns it down to press a
    # button on the microwave's top
    pitch: float | None = None
    # ... and its roll about its own pointing axis (rad, with a pitch; None: keep): a
    # level hand rolled a quarter turn closes its fingers vertically, across a bar handle
    roll: float | None = None


@dataclass
class Retry:
    """Phases built afresh and run again until `check()` holds (a missed grasp)."""

    build: Callable[[], list[Phase]]
    check: Callable[[], bool]
    tries: int = 3


def yaw_of(mat: np.ndarray) -> float:
    return float(np.arctan2(mat[1, 0], mat[0, 0]))


def wrap_angle(angle: float, period: float) -> float:
    """Angle folded into [-period/2, period/2) (symmetric grasps)."""
    return float((angle + period / 2) % period - period / 2)


def grasp_yaw(
    sim: SimEnv, obj: str, period: float, offset: float = 0.0, near: str | None = None
) -> float:
    """Gripper yaw that lines the fingers up with the object's faces (mod `period`).

    At yaw 0 the fingers close along world y; `offset` turns them to pinch across the
    object's x extent instead (a cereal box is only thin along x).
    """
    geoms = [g for g, o in sim._geom_owner.items() if o == obj and sim.model.geom_contype[g]]
    if geoms and near is not None:  # the collision geom closest to the grasp point
        at = sim.point(near)
        geoms.sort(key=lambda g: float(np.linalg.norm(sim.data.geom_xpos[g] - at)))
    if geoms:  # the collision box's frame (a mesh object's body frame may be turned)
        mat = sim.data.geom_xmat[geoms[0]].reshape(3, 3)
    else:
        mat = sim.data.xmat[sim._body_id(sim.spec.object_spec(obj).body)].reshape(3, 3)
    return wrap_angle(yaw_of(mat) + offset, period)


CLEAR_GAP = 0.06  # m: fingers this far from every other object are clear of them


def clear_yaw(sim: SimEnv, obj: str) -> float:
    """For a round object: the yaw nearest the start pose (0) whose fingers land at least
    `CLEAR_GAP` from other objects, else the one whose fingers land farthest from them.

    Staying near 0 leaves the wrist room to turn on the way to a far goal: a can picked
    at a quarter turn reaches the far PickPlace bin with its last joint at its limit.
    """
    centre = sim.point(obj)[:2]
    others = [sim.point(o.name)[:2] for o in sim.spec.objects if o.name != obj]
    if not others:
        return 0.0
    gaps = {}
    for yaw in np.linspace(0.0, np.pi, 8, endpoint=False):
        axis = np.array([-np.sin(yaw), np.cos(yaw)])
        fingers = [centre + 0.05 * axis, centre - 0.05 * axis]
        gaps[wrap_angle(float(yaw), np.pi)] = min(
            float(np.linalg.norm(f - p)) for f in fingers for p in others
        )
    clear = [y for y, g in gaps.items() if g >= CLEAR_GAP]
    if clear:
        return min(clear, key=abs)
    return max(gaps, key=lambda y: (round(gaps[y], 3), -abs(y)))


def pick_phases(
    sim: SimEnv, obj: str, period: float | None, grasp_dz: float = 0.0, point: str | None = None
) -> list[Phase]:
    """Approach from above, descend, close, lift.

    With `point` (a handle site), the grasp sits `OUTWARD[obj]` further out along the
    handle, away from the object's centre (keeps the palm clear of a peg).
    """
    where = point or obj
    out = OUTWARD.get(obj, 0.0)

    def grip_point() -> np.ndarray:
        p = sim.point(where)
        if out:
            d = p - sim.point(obj)
            d[2] = 0.0
            p = p + out * d / max(float(np.linalg.norm(d)), 1e-6)
        return p

    def above() -> np.ndarray:
        return grip_point() + np.array([0, 0, 0.10 + grasp_dz])

    def at() -> np.ndarray:
        return grip_point() + np.array([0, 0, grasp_dz])

    turn = YAW_OFFSET.get(obj, 0.0)
    if period:
        yaw = lambda: grasp_yaw(sim, obj, period, turn, point)  # noqa: E731
    else:
        yaw = lambda: clear_yaw(sim, obj)  # noqa: E731
    hold = [None]

    def here() -> np.ndarray:
        return hold[0]

    def freeze() -> np.ndarray:
        if hold[0] is None:
            hold[0] = sim.point("eef")
        return hold[0]

    start_z = sim.point(obj)[2]
    return [
        Phase(above, OPEN, tol=0.015, steps=80, yaw=yaw),
        Phase(at, OPEN, tol=0.006, steps=40, gain=1.5),
        Phase(freeze, CLOSE, tol=None, steps=10),
        Phase(
            lambda: here() + np.array([0, 0, start_z + 0.15 - here()[2]]), CLOSE, 0.02, 60, gain=0.6
        ),
    ]


_SIGNS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])


def object_z_range(sim: SimEnv, obj: str) -> tuple[float, float]:
    """Lowest and highest world z of the object's collision geoms (bounding-box corners)."""
    low, high = np.inf, -np.inf
    for g, owner in sim._geom_owner.items():
        if owner != obj or not sim.model.geom_contype[g]:
            continue
        centre, half = sim.model.geom_aabb[g][:3], sim.model.geom_aabb[g][3:]
        z = ((centre + _SIGNS * half) @ sim.data.geom_xmat[g].reshape(3, 3).T)[:, 2]
        z = z + sim.data.geom_xpos[g][2]
        low, high = min(low, float(z.min())), max(high, float(z.max()))
    if not np.isfinite(low):
        z = float(sim.point(obj)[2])
        return z, z
    return low, high


def object_bottom(sim: SimEnv, obj: str) -> float:
    return object_z_range(sim, obj)[0]


def place_phases(
    sim: SimEnv, goal: str, drop_dz: float, carry_z: float, obj: str | None = None
) -> list[Phase]:
    """Carry over the goal at `carry_z`, lower to `drop_dz` above it, release, retreat.

    With `obj`, the goal is a floor (a bin): the held object's bottom is lowered to
    `drop_dz` above it, however far below the fingers the object reaches.
    """

    def reach() -> float:  # how far the held object hangs below the grip point
        if not obj:
            return 0.0
        return float(np.clip(sim.point("eef")[2] - object_bottom(sim, obj), 0.0, 0.2))

    held = obj
    tops = [object_z_range(sim, o.name)[1] for o in sim.spec.objects if o.name != held]

    def safe_z() -> float:  # the load clears every other object
        return max(tops, default=0.0) + reach() + 0.05

    def over() -> np.ndarray:
        g = sim.point(goal)
        return np.array([g[0], g[1], max(carry_z, g[2] + reach() + 0.12, safe_z())])

    def rise() -> np.ndarray:  # straight up first, then across
        e = sim.point("eef")
        return np.array([e[0], e[1], over()[2]])

    def down() -> np.ndarray:
        return sim.point(goal) + np.array([0, 0, drop_dz + reach()])

    rest = [None]

    def freeze() -> np.ndarray:
        if rest[0] is None:
            rest[0] = sim.point("eef")
        return rest[0]

    return [
        Phase(rise, CLOSE, tol=0.02, steps=40, gain=0.6),
        Phase(over, CLOSE, tol=0.02, steps=120, gain=0.6),
        Phase(down, CLOSE, tol=0.01, steps=50),
        Phase(freeze, OPEN, tol=None, steps=8),
        Phase(lambda: freeze() + np.array([0, 0, 0.08]), OPEN, tol=0.02, steps=20),
    ]


# grasp symmetry about the vertical axis, per object (None: round, any yaw works)
PERIOD = {
    "cube": np.pi / 2,
    "red cube": np.pi / 2,
    "can": None,
    "milk": np.pi / 2,
    "bread": np.pi,
    "cereal": np.pi,
}


# tall objects: grasp this far above their centre so the palm clears their top (m)
GRASP_DZ = {"milk": 0.045, "cereal": 0.035}
YAW_OFFSET = {"cereal": np.pi / 2}
OUTWARD = {"square nut": 0.0}


def pick_retry(sim: SimEnv, obj: str, period, dz: float = 0.0, point=None) -> Retry:
    return Retry(
        lambda: pick_phases(sim, obj, period, dz, point),
        lambda: sim.predicate(f"lifted:{obj}"),
    )
