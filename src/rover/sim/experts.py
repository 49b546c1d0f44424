"""Scripted experts: closed-loop waypoint controllers on Panda with OSC_POSE actions.

Each expert is a list of phases. A phase names a target for the end effector (a function
of the current state, so the script reacts to where objects really are), a gripper
command and when it is done (target reached, a step budget, or both). Actions are
OSC_POSE deltas: position error scaled to the controller's 5 cm per step and the
orientation error (keep pointing down, turn to the grasp yaw) as an axis-angle delta.
The recorded demonstration is the robomimic layout: `states[t]` is the state before
`actions[t]`; the final action is a hold, so the last state is the finished task.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from rover.sim.env import SimEnv

OPEN, CLOSE = -1.0, 1.0
POS_SCALE = 0.05  # m per unit action (robosuite OSC_POSE output_max)
ROT_SCALE = 0.5  # rad per unit action
ROT_TOL = 0.08  # rad: a waypoint counts as reached only once the hand is turned too


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


@dataclass
class Retry:
    """Phases built afresh and run again until `check()` holds (a missed grasp)."""

    build: Callable[[], list[Phase]]
    check: Callable[[], bool]
    tries: int = 3


@dataclass
class Demo:
    """One expert demonstration: per-step states (before each action) and actions."""

    states: np.ndarray  # (T, S)
    actions: np.ndarray  # (T, A)
    success: bool
    subtask_ends: list[int]  # first step index at which each subtask's end signal holds


def _yaw_of(mat: np.ndarray) -> float:
    return float(np.arctan2(mat[1, 0], mat[0, 0]))


def _wrap(angle: float, period: float) -> float:
    """Angle folded into [-period/2, period/2) (symmetric grasps)."""
    return float((angle + period / 2) % period - period / 2)


class Scripted:
    """Runs phases on a SimEnv, recording states and actions."""

    def __init__(self, sim: SimEnv) -> None:
        self.sim = sim
        self.down = sim.data.site_xmat[sim._eef_site].reshape(3, 3).copy()
        self.yaw0 = 0.0
        self.tilt = 0.0  # rotation about world x applied before the yaw (door handle)
        self.states: list[np.ndarray] = []
        self.actions: list[np.ndarray] = []

    def rot_error(self, yaw: float) -> np.ndarray:
        """Axis-angle (world frame) from the current hand orientation to the wanted one."""
        cur = self.sim.data.site_xmat[self.sim._eef_site].reshape(3, 3)
        want = Rotation.from_euler("zx", [yaw, self.tilt]).as_matrix() @ self.down
        return Rotation.from_matrix(want @ cur.T).as_rotvec()

    def action(self, target: np.ndarray, grip: float, yaw: float, gain: float) -> np.ndarray:
        err = target - self.sim.point("eef")
        pos = np.clip(gain * err / POS_SCALE, -1.0, 1.0)
        rot = np.clip(self.rot_error(yaw) / ROT_SCALE, -1.0, 1.0)
        return np.concatenate([pos, rot, [grip]])

    def run(self, phase: Phase) -> None:
        yaw = self.yaw0 if phase.yaw is None else phase.yaw()
        self.yaw0 = yaw
        for k in range(phase.steps):
            if phase.done is not None and phase.done():
                return
            if phase.track_yaw and phase.yaw is not None:
                yaw = phase.yaw()
            target = phase.target()
            if (
                phase.tol is not None
                and k >= phase.min_steps
                and np.linalg.norm(target - self.sim.point("eef")) < phase.tol
                and np.linalg.norm(self.rot_error(yaw)) < ROT_TOL
            ):
                return
            act = self.action(target, phase.grip, yaw, phase.gain)
            self.states.append(self.sim.get_state())
            self.actions.append(act)
            self.sim.step(act)


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
    return _wrap(_yaw_of(mat) + offset, period)


def clear_yaw(sim: SimEnv, obj: str) -> float:
    """For a round object: the yaw whose fingers land farthest from other objects."""
    centre = sim.point(obj)[:2]
    others = [sim.point(o.name)[:2] for o in sim.spec.objects if o.name != obj]
    if not others:
        return 0.0
    best, best_gap = 0.0, -1.0
    for yaw in np.linspace(0.0, np.pi, 8, endpoint=False):
        axis = np.array([-np.sin(yaw), np.cos(yaw)])
        fingers = [centre + 0.05 * axis, centre - 0.05 * axis]
        gap = min(float(np.linalg.norm(f - p)) for f in fingers for p in others)
        if gap > best_gap + 1e-3:
            best, best_gap = _wrap(float(yaw), np.pi), gap
    return best


def pick_phases(
    sim: SimEnv, obj: str, period: float | None, grasp_dz: float = 0.0, point: str | None = None
) -> list[Phase]:
    """Approach from above, descend, close, lift.

    With `point` (a handle site), the grasp sits `_OUTWARD[obj]` further out along the
    handle, away from the object's centre (keeps the palm clear of a peg).
    """
    where = point or obj
    out = _OUTWARD.get(obj, 0.0)

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

    turn = _YAW_OFFSET.get(obj, 0.0)
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
_PERIOD = {
    "cube": np.pi / 2,
    "red cube": np.pi / 2,
    "can": None,
    "milk": np.pi / 2,
    "bread": np.pi,
    "cereal": np.pi,
}


# tall objects: grasp this far above their centre so the palm clears their top (m)
_GRASP_DZ = {"milk": 0.045, "cereal": 0.035}
_YAW_OFFSET = {"cereal": np.pi / 2}
_OUTWARD = {"square nut": 0.015}


def _pick_retry(sim: SimEnv, obj: str, period, dz: float = 0.0, point=None) -> Retry:
    return Retry(
        lambda: pick_phases(sim, obj, period, dz, point),
        lambda: sim.predicate(f"lifted:{obj}"),
    )


def _pick_place_script(sim: SimEnv) -> list[Phase | Retry]:
    phases: list[Phase | Retry] = []
    subs = sim.spec.subtasks
    home = sim.point("eef")
    for k, (grasp, move) in enumerate(zip(subs[0::2], subs[1::2], strict=True)):
        obj = grasp.object
        if k:  # back to the start pose first: from the far bin the arm cannot turn well
            phases.append(Phase(lambda: home, OPEN, tol=0.03, steps=60, yaw=lambda: 0.0))
        phases.append(_pick_retry(sim, obj, _PERIOD.get(obj), _GRASP_DZ.get(obj, 0.0)))
        into_bin = move.end_signal.startswith("placed")
        carry = sim.point(move.goal)[2] + 0.20
        phases += place_phases(
            sim, move.goal, 0.03, carry, obj=move.object if into_bin else None
        )
    return phases


def _nut_script(sim: SimEnv) -> list[Phase | Retry]:
    grasp, move = sim.spec.subtasks
    nut = grasp.object
    phases = [_pick_retry(sim, nut, np.pi, point=f"{nut}:handle")]
    hand0 = sim.data.site_xmat[sim._eef_site].reshape(3, 3).copy()  # hand at reset
    table_z = float(sim.env.table_offset[2])

    def held_offset() -> np.ndarray:
        return sim.point("eef") - sim.point(nut)

    def over() -> np.ndarray:
        g = sim.point(move.goal) + held_offset()
        return np.array([g[0], g[1], table_z + 0.20])

    def down() -> np.ndarray:
        g = sim.point(move.goal) + held_offset()
        return np.array([g[0], g[1], table_z + 0.03])

    rest = [None]

    def let_go() -> np.ndarray:
        if rest[0] is None:
            rest[0] = sim.point("eef")
        return rest[0]

    turn: list[float] = []

    def carry_yaw() -> float:
        # turn the nut by a multiple of 90 degrees (the peg is square) so its handle, and
        # the hand holding it, point back toward the robot: a far peg stays reachable
        if not turn:
            d = (sim.point(f"{nut}:handle") - sim.point(nut))[:2]
            now = float(np.arctan2(d[1], d[0]))
            best = min((-1, 0, 1), key=lambda k: abs(_wrap(now + k * np.pi / 2 - np.pi, 2 * np.pi)))
            cur = sim.data.site_xmat[sim._eef_site].reshape(3, 3)
            turn.append(_yaw_of(cur @ hand0.T) + best * np.pi / 2)
        return turn[0]

    return phases + [
        Phase(over, CLOSE, tol=0.006, steps=120, gain=1.2, yaw=carry_yaw),
        Phase(over, CLOSE, tol=None, steps=10, gain=1.2),  # let the hanging nut settle
        Phase(down, CLOSE, tol=0.01, steps=60, gain=0.4),
        Phase(let_go, OPEN, tol=None, steps=15),
        Phase(lambda: let_go() + np.array([0, 0, 0.08]), OPEN, tol=0.02, steps=20),
    ]


def _lift_script(sim: SimEnv) -> list[Phase | Retry]:
    phases: list[Phase | Retry] = [_pick_retry(sim, "cube", _PERIOD["cube"])]
    top = [None]

    def stay() -> np.ndarray:
        if top[0] is None:
            top[0] = sim.point("eef")
        return top[0]

    return phases + [Phase(stay, CLOSE, tol=None, steps=10)]


def _door_script(sim: SimEnv) -> list[Phase]:
    goal = sim.spec.goals["door_open"].angle
    hold = [None]

    def freeze() -> np.ndarray:
        if hold[0] is None:
            hold[0] = sim.point("eef")
        return hold[0]

    def handle() -> np.ndarray:
        return sim.point("door:handle")

    def pull() -> np.ndarray:
        # a point a little further along the handle's arc: the door swings open
        return sim._door_handle_at(sim.hinge_angle() + 0.12)

    rest = [None]

    def let_go() -> np.ndarray:
        if rest[0] is None:
            rest[0] = sim.point("eef")
        return rest[0]

    return [
        Phase(lambda: handle() + np.array([0, 0, 0.08]), OPEN, tol=0.015, steps=80),
        Phase(handle, OPEN, tol=0.006, steps=40, gain=1.5),
        Phase(freeze, CLOSE, tol=None, steps=10),
        Phase(
            pull,
            CLOSE,
            tol=None,
            steps=150,
            yaw=sim.hinge_angle,
            track_yaw=True,
            gain=0.6,
            done=lambda: sim.hinge_angle() > goal + 0.03,
        ),
        Phase(let_go, OPEN, tol=None, steps=8),
        Phase(lambda: let_go() + np.array([0.0, 0.06, 0.06]), OPEN, tol=0.015, steps=20),
    ]


# the door handle sits close to the panel: lean the hand away from it (rad about x)
_TILT = {"door": -0.6}

SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {
    "lift": _lift_script,
    "pick_place": _pick_place_script,
    "stack": _pick_place_script,
    "door": _door_script,
    "nut": _nut_script,
}


def run_expert(sim: SimEnv, seed: int) -> Demo:
    """Reset to `seed` and run the task's scripted expert; return the demonstration."""
    sim.reset(seed)
    script = Scripted(sim)
    script.tilt = _TILT.get(sim.spec.expert, 0.0)
    for item in SCRIPTS[sim.spec.expert](sim):
        if isinstance(item, Retry):
            for _ in range(item.tries):
                for phase in item.build():
                    script.run(phase)
                if item.check() or len(script.actions) >= sim.spec.max_expert_steps:
                    break
        else:
            script.run(item)
        if len(script.actions) >= sim.spec.max_expert_steps:
            break
    # final hold: the last recorded state is the finished task
    hold = np.zeros(len(sim.action_low))
    hold[-1] = script.actions[-1][-1] if script.actions else OPEN
    script.states.append(sim.get_state())
    script.actions.append(hold)
    states = np.stack(script.states)
    ends = subtask_ends(sim, states)
    sim.set_state(states[-1])
    return Demo(
        states=states,
        actions=np.stack(script.actions),
        success=sim.success() and len(ends) == len(sim.spec.subtasks),
        subtask_ends=ends,
    )


def subtask_ends(sim: SimEnv, states: np.ndarray) -> list[int]:
    """First step at which each subtask's end signal holds, subtasks taken in order."""
    ends: list[int] = []
    k = 0
    subs = sim.spec.subtasks
    for t, s in enumerate(states):
        if k >= len(subs):
            break
        sim.set_state(s)
        if sim.predicate(subs[k].end_signal):
            ends.append(t)
            k += 1
    return ends
