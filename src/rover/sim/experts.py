"""Scripted experts: closed-loop waypoint controllers on Panda with OSC_POSE actions.

Each expert is a list of phases (`rover.sim.motions`). Actions are OSC_POSE deltas:
position error scaled to the controller's 5 cm per step and the orientation error (keep
pointing down, turn to the grasp yaw) as an axis-angle delta. The recorded
demonstration is the robomimic layout: `states[t]` is the state before `actions[t]`;
the final action is a hold, so the last state is the finished task.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from rover.sim.env import SimEnv
from rover.sim.experts_articulated import SCRIPTS as ARTICULATED_SCRIPTS
from rover.sim.kitchen.experts import SCRIPTS as KITCHEN_SCRIPTS
from rover.sim.kitchen.forward_chain import SCRIPTS as FORWARD_CHAIN_SCRIPTS
from rover.sim.kitchen.forward_grasp import FORWARD_PITCH, HAND_DOWN
from rover.sim.kitchen.forward_grasp import SCRIPTS as FORWARD_SCRIPTS
from rover.sim.kitchen.thawing_expert import SCRIPTS as THAWING_SCRIPTS
from rover.sim.motions import (
    CLOSE,
    GRASP_DZ,
    OPEN,
    PERIOD,
    Phase,
    Retry,
    pick_retry,
    place_phases,
    wrap_angle,
    yaw_of,
)

POS_SCALE = 0.05  # m per unit action (robosuite OSC_POSE output_max)
ROT_SCALE = 0.5  # rad per unit action
ROT_TOL = 0.08  # rad: a waypoint counts as reached only once the hand is turned too
MAX_WRIST_YAW = 1.6  # rad from the start pose the scripts may turn the hand about z
# a waypoint phase also ends once the hand is stuck near its target: over the last
# STUCK_STEPS steps the error shrank less than STUCK_GAIN while within STUCK_REACH
# tolerances of it. At the edge of the workspace (the far PickPlace bin) the controller
# settles 2-5 cm short and the phase would otherwise burn its whole step budget with
# the hand still (a visible stall of up to 170 steps); the next phase starts from there.
STUCK_STEPS = 10
STUCK_GAIN = 0.002  # m ...
STUCK_TURN = 0.02  # ... and the turn to the wanted orientation less than this (rad)
STUCK_REACH = 3.0


@dataclass
class Demo:
    """One expert demonstration: per-step states (before each action) and actions."""

    states: np.ndarray  # (T, S)
    actions: np.ndarray  # (T, A)
    success: bool
    subtask_ends: list[int]  # first step index at which each subtask's end signal holds


class Scripted:
    """Runs phases on a SimEnv, recording states and actions."""

    def __init__(self, sim: SimEnv) -> None:
        self.sim = sim
        self.down = sim.data.site_xmat[sim._eef_site].reshape(3, 3).copy()
        self.yaw0 = 0.0
        self.tilt = 0.0  # rotation about world x applied before the yaw (door handle)
        # rotation about world y applied before the yaw: -pi/2 points the hand forward
        # (+x, fingers closing along y) for the forward grasp into low openings
        self.pitch = 0.0
        self.roll = 0.0  # rad about the hand's own pointing axis, applied before the pitch
        self.states: list[np.ndarray] = []
        self.actions: list[np.ndarray] = []

    def rot_error(self, yaw: float) -> np.ndarray:
        """Axis-angle (world frame) from the current hand orientation to the wanted one."""
        cur = self.sim.data.site_xmat[self.sim._eef_site].reshape(3, 3)
        if self.pitch:  # (at hand down the pointing axis is world z: roll first)
            turn = Rotation.from_euler("zyz", [self.roll, self.pitch, yaw])
            want = turn.as_matrix() @ self.down
        else:
            want = Rotation.from_euler("zx", [yaw, self.tilt]).as_matrix() @ self.down
        return Rotation.from_matrix(want @ cur.T).as_rotvec()

    def action(self, target: np.ndarray, grip: float, yaw: float, gain: float) -> np.ndarray:
        err = target - self.sim.point("eef")
        pos = np.clip(gain * err / POS_SCALE, -1.0, 1.0)
        rot = np.clip(self.rot_error(yaw) / ROT_SCALE, -1.0, 1.0)
        return np.concatenate([pos, rot, [grip]])

    def run(self, phase: Phase) -> None:
        if phase.pitch is not None:
            self.pitch = phase.pitch
        if phase.roll is not None:
            self.roll = phase.roll
        yaw = self.yaw0 if phase.yaw is None else phase.yaw()
        self.yaw0 = yaw
        errs: list[tuple[float, float]] = []  # (position error m, orientation error rad)
        for k in range(phase.steps):
            if phase.done is not None and phase.done():
                return
            if phase.track_yaw and phase.yaw is not None:
                yaw = phase.yaw()
            target = phase.target()
            if phase.tol is not None and k >= phase.min_steps:
                err = float(np.linalg.norm(target - self.sim.point("eef")))
                turn = float(np.linalg.norm(self.rot_error(yaw)))
                errs.append((err, turn))
                if err < phase.tol and turn < ROT_TOL:
                    return
                if (
                    len(errs) > STUCK_STEPS
                    and err < STUCK_REACH * phase.tol
                    and errs[-1 - STUCK_STEPS][0] - err < STUCK_GAIN
                    and errs[-1 - STUCK_STEPS][1] - turn < STUCK_TURN
                ):
                    return
            act = self.action(target, phase.grip, yaw, phase.gain)
            self.states.append(self.sim.get_state())
            self.actions.append(act)
            self.sim.step(act)


def _pick_place_script(sim: SimEnv) -> list[Phase | Retry]:
    phases: list[Phase | Retry] = []
    subs = sim.spec.subtasks
    home = sim.point("eef")
    for k, (grasp, move) in enumerate(zip(subs[0::2], subs[1::2], strict=True)):
        obj = grasp.object
        if k:  # back to the start pose first: from the far bin the arm cannot turn well
            phases.append(Phase(lambda: home, OPEN, tol=0.03, steps=60))
        phases.append(pick_retry(sim, obj, PERIOD.get(obj), GRASP_DZ.get(obj, 0.0)))
        into_bin = move.end_signal.startswith("placed")
        carry = sim.point(move.goal)[2] + 0.20
        phases += place_phases(sim, move.goal, 0.03, carry, obj=move.object if into_bin else None)
    return phases


def _nut_script(sim: SimEnv) -> list[Phase | Retry]:
    grasp, move = sim.spec.subtasks
    nut = grasp.object
    phases = [pick_retry(sim, nut, np.pi, point=f"{nut}:handle")]
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
    square = nut.startswith("square")

    def carry_yaw() -> float:
        # turn the nut by a multiple of 90 degrees (the peg is square) so its handle, and
        # the hand holding it, point back toward the robot: a far peg stays reachable
        if not turn:
            d = (sim.point(f"{nut}:handle") - sim.point(nut))[:2]
            now = float(np.arctan2(d[1], d[0]))
            cur = sim.data.site_xmat[sim._eef_site].reshape(3, 3)
            yaw = yaw_of(cur @ hand0.T)
            if square:  # a square nut only slides down a square peg with edges lined up
                body = sim.data.xmat[sim._body_id(sim.spec.object_spec(nut).body)]
                yaw -= wrap_angle(yaw_of(body.reshape(3, 3)), np.pi / 2)
                now -= wrap_angle(yaw_of(body.reshape(3, 3)), np.pi / 2)
            # only turns the wrist can make without nearing its joint limit
            ks = [k for k in (-1, 0, 1) if abs(yaw + k * np.pi / 2) <= MAX_WRIST_YAW] or [0]
            best = min(ks, key=lambda k: abs(wrap_angle(now + k * np.pi / 2 - np.pi, 2 * np.pi)))
            turn.append(yaw + best * np.pi / 2)
        return turn[0]

    return phases + [
        Phase(over, CLOSE, tol=0.004, steps=120, gain=1.2, yaw=carry_yaw),
        Phase(over, CLOSE, tol=None, steps=20, gain=1.2),  # let the hanging nut settle
        Phase(down, CLOSE, tol=0.01, steps=60, gain=0.4),
        Phase(let_go, OPEN, tol=None, steps=15),
        Phase(lambda: let_go() + np.array([0, 0, 0.08]), OPEN, tol=0.02, steps=20),
    ]


def _lift_script(sim: SimEnv) -> list[Phase | Retry]:
    phases: list[Phase | Retry] = [pick_retry(sim, "cube", PERIOD["cube"])]
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
SCRIPTS.update(ARTICULATED_SCRIPTS)  # drawer, button, knob (rover's own fixtures)
SCRIPTS.update(KITCHEN_SCRIPTS)  # kitchen dials and hinged parts, either direction
SCRIPTS.update(FORWARD_SCRIPTS)  # the forward grasp into the microwave, cabinet, coffee slot
SCRIPTS.update(FORWARD_CHAIN_SCRIPTS)  # ... chained: RestockPantry, PrepareCoffee
_PITCH = {name: FORWARD_PITCH for name in (*FORWARD_SCRIPTS, *FORWARD_CHAIN_SCRIPTS)}
SCRIPTS.update(THAWING_SCRIPTS)  # MicrowaveThawing: level hand, turned down to press start
_PITCH.update({name: FORWARD_PITCH for name in THAWING_SCRIPTS})


def run_expert(sim: SimEnv, seed: int) -> Demo:
    """Reset to `seed` and run the task's scripted expert; return the demonstration."""
    sim.reset(seed)
    script = Scripted(sim)
    script.tilt = _TILT.get(sim.spec.expert, 0.0)
    script.pitch = _PITCH.get(sim.spec.expert, 0.0)
    if script.pitch:  # the arm starts with the hand level: pitch from the hand-down frame
        script.down = np.array(HAND_DOWN)
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
