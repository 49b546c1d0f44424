"""The chained scripted expert of kitchen.MicrowaveThawing (`rover.sim.kitchen.thawing`).

From the forward grasp's level-hand ready pose (`forward_grasp.READY_Q`), five legs:

1. **open the door by hooking its handle**: the microwave's handle is a horizontal bar
   8 cm proud of the door, parallel to it, and a level hand's fingers close
   horizontally, along the bar, so they cannot grip it. The closed fingers go over the
   bar, drop into the gap between bar and door and pull it along its arc, the hand's yaw
   turning with the door so they stay behind the bar;
2. **pick the food** from the counter beside the microwave (`forward_pick`);
3. **place it in the cavity** (`forward_place`, into the opening);
4. **push the door shut from outside**: the closed fingertips against the door's outer
   face under the handle, pushed along the door's inward normal as it swings back;
5. **press the start button** on the microwave's top: the hand turns down
   (`Phase.pitch`) above the button, as the button task's expert presses it, and
   tries again turned a little either way while the button is not down.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.experts_articulated import latch
from rover.sim.kitchen.forward_grasp import (
    FORWARD_PITCH,
    approach_yaw,
    forward_pick,
    forward_place,
    region_floor_z,
)
from rover.sim.motions import CLOSE, OPEN, Phase, Retry

BAR_ROLL = float(-np.pi / 2)  # rad the level hand rolls: fingers close vertically
BAR_IN = 0.004  # m past the bar's centre line (toward the door) the grip point goes
# the share of the door's swing the hand's yaw follows while pulling: turned with it all
# the way, the arm ran joints 2 and 5 into their limits 0.8 rad into the swing (the
# grip's pads turn on the bar)
YAW_MAX = 0.7
PULL_LEAD = 0.15  # rad along the arc the pull target runs ahead of the door
PUSH_LEAD = 0.15  # rad ... and the push target while shutting it
# shutting: the hand's left face (10.4 cm from the grip point, 4-10 cm behind it) pushes
# the bar while the door stands open past `SIDE_UNTIL`, then the fingertips do
SIDE_AHEAD = 0.07  # m the grip point stands ahead of the bar (the hand's face beside it)
SIDE_OFF = 0.112  # m the grip point stands right of the bar
SIDE_UNTIL = 0.6  # rad
OVER_DOOR = 0.16  # m above the bar the hand passes over the open door
# swinging it wide: the door's free edge, inner corner, from the handle's centre (along
# the door's inward normal, along the door toward the free edge), the hand's right face
# (10.4 cm right of the grip point) against it at mid height
EDGE_FROM_HANDLE = (0.08, -0.0825)
EDGE_DZ = 0.0
EDGE_AHEAD = 0.07
EDGE_OFF = 0.112
CLEAR_AHEAD = np.array([0.12, 0.0, 0.05])  # m from the ready pose's grip point
PULL_UNTIL = 0.8  # rad the pull by the handle takes the door before the push takes over
TIP_BACK = 0.018  # m: the grip point this far in front of the bar (fingertips on it)
LIFT_OFF = np.array([0.0, 0.0, 0.06])  # m the hand rises off the shut door's bar
PRESS_TILT = 0.35  # rad the hand tilts down from level to press the start button
# rad off the fixture's yaw the pressing hand turns, one per try: which one leaves
# wrist joint 5 inside its limit over the button depends on the scene (seeds 0, 13, 14)
PRESS_YAWS = (0.0, -0.3, 0.3)
TIP_DZ = 0.012  # m above the button's top the grip point presses (the finger's half width)


def _inward(yaw: float) -> np.ndarray:
    return np.array([np.cos(yaw), np.sin(yaw), 0.0])


def open_door_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Grasp the handle's bar from the front, the level hand rolled a quarter turn so its
    fingers close vertically across it, and pull it along the door's arc, the hand
    turning with the door."""
    env = sim.env
    psi = approach_yaw(sim)

    def door_q() -> float:
        with env.working(key):
            return env.joint_value()

    def door_yaw() -> float:  # the door's inward normal
        return psi + door_q()

    def hand_yaw() -> float:  # the hand turns with the door, up to `YAW_MAX`
        return psi + min(door_q(), YAW_MAX)

    def handle() -> np.ndarray:
        return sim.point("microwave door:handle") + BAR_IN * _inward(door_yaw())

    def ahead() -> np.ndarray:
        with env.working(key):
            q = min(env.joint_value() + PULL_LEAD, env.target + 0.1)
            return env.site_at("handle", q) + BAR_IN * _inward(psi + q)

    def done() -> bool:
        return door_q() >= PULL_UNTIL

    hold = latch(sim)
    return [
        Phase(
            lambda: handle() - 0.1 * _inward(door_yaw()),
            OPEN,
            tol=0.012,
            steps=120,
            yaw=door_yaw,
            roll=BAR_ROLL,
        ),
        Phase(handle, OPEN, tol=0.006, steps=60, gain=1.2),
        Phase(hold, CLOSE, tol=None, steps=10),
        Phase(ahead, CLOSE, tol=None, steps=220, gain=0.8, yaw=hand_yaw, track_yaw=True, done=done),
    ]


def swing_wide_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Let go of the half-open door, pass over it and push its free edge on round from
    the inside with the right face of the level, unturned hand, to the target angle."""
    env = sim.env
    psi = approach_yaw(sim)
    fwd = _inward(psi)
    left = _inward(psi + np.pi / 2)

    def door_q() -> float:
        with env.working(key):
            return env.joint_value()

    def edge(q_ahead: float = 0.0) -> np.ndarray:  # the free edge's inner corner
        with env.working(key):
            q = min(env.joint_value() + q_ahead, env.target + 0.15)
            dq = q - env.joint_value()
        hinge = sim.data.xanchor[env.joint_id].copy()
        corner = sim.point("microwave door:handle") + EDGE_FROM_HANDLE[0] * _inward(psi + door_q())
        corner += EDGE_FROM_HANDLE[1] * _inward(psi + door_q() + np.pi / 2)
        v = corner - hinge
        c, s_ = np.cos(dq), np.sin(dq)
        turned = np.array([c * v[0] - s_ * v[1], s_ * v[0] + c * v[1], v[2]])
        return hinge + turned + np.array([0.0, 0.0, EDGE_DZ])

    def beside(q_ahead: float = 0.0) -> np.ndarray:  # the hand's right face at the edge
        return edge(q_ahead) + EDGE_AHEAD * fwd + EDGE_OFF * left

    def done() -> bool:
        with env.working(key):
            return env.progress() >= 0.97

    rest = latch(sim)
    over = np.array([0.0, 0.0, OVER_DOOR])
    turn = lambda: psi  # noqa: E731
    return [
        Phase(rest, OPEN, tol=None, steps=8),
        Phase(lambda: rest() - 0.08 * _inward(psi + door_q()), OPEN, tol=0.02, steps=40),
        Phase(lambda: rest() - 0.08 * _inward(psi + door_q()) + over, CLOSE, tol=0.02, steps=40),
        Phase(
            lambda: beside() + 0.03 * left + over, CLOSE, tol=0.02, steps=100, yaw=turn, roll=0.0
        ),
        Phase(lambda: beside() + 0.03 * left, CLOSE, tol=0.015, steps=80),
        Phase(lambda: beside(PUSH_LEAD), CLOSE, tol=None, steps=160, gain=0.8, done=done),
        Phase(lambda: beside() + 0.06 * left, CLOSE, tol=0.02, steps=30),
    ]


def shut_door_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Push the door shut from outside by its handle, the hand level and unturned:
    first with the side of the hand against the bar while the door stands wide (its
    outer face looks along the counter), then with the fingertips on the bar's front."""
    env = sim.env
    psi = approach_yaw(sim)
    fwd = _inward(psi)
    left = _inward(psi + np.pi / 2)

    def bar(q_back: float = 0.0) -> np.ndarray:
        with env.working(key):
            q = max(env.joint_value() - q_back, -0.05)
            return env.site_at("handle", q)

    def door_q() -> float:
        with env.working(key):
            return env.joint_value()

    def side(q_back: float = 0.0) -> np.ndarray:  # the hand's left face on the bar
        return bar(q_back) + SIDE_AHEAD * fwd - SIDE_OFF * left

    def front(q_back: float = 0.0) -> np.ndarray:  # the fingertips on the bar's front
        return bar(q_back) - TIP_BACK * _inward(psi + door_q())

    def wide() -> bool:
        return door_q() <= SIDE_UNTIL

    def done() -> bool:
        with env.working(key):
            return env.progress() >= 0.98

    turn = lambda: psi  # noqa: E731
    start, end = latch(sim), latch(sim)
    over = np.array([0.0, 0.0, OVER_DOOR])
    return [
        # over the open door to its outer side (straight across, the hand swung it wide)
        Phase(lambda: start() + over, CLOSE, tol=0.02, steps=40, yaw=turn),
        Phase(lambda: side() - 0.06 * left + over, CLOSE, tol=0.02, steps=100),
        Phase(lambda: side() - 0.06 * left, CLOSE, tol=0.015, steps=80),
        Phase(side, CLOSE, tol=0.012, steps=40),
        Phase(lambda: side(PUSH_LEAD), CLOSE, tol=None, steps=150, gain=0.8, done=wide),
        Phase(lambda: side() - 0.08 * left - 0.06 * fwd, CLOSE, tol=0.02, steps=40),
        Phase(lambda: front() - 0.08 * fwd, CLOSE, tol=0.015, steps=60),
        Phase(front, CLOSE, tol=0.01, steps=40),
        Phase(lambda: front(PUSH_LEAD), CLOSE, tol=None, steps=150, gain=0.8, done=done),
        # up off the bar before backing away: fingertips that slid over it into the gap
        # behind it hooked it, and backing straight out pulled the shut door ajar again
        Phase(lambda: end() + LIFT_OFF, CLOSE, tol=0.015, steps=40),
        Phase(lambda: end() + LIFT_OFF - 0.1 * fwd, CLOSE, tol=0.02, steps=40),
    ]


def press_button(sim: SimEnv, key: str) -> Retry:
    """Press the start button with the fingertips, the hand tilted a little down from
    level (its palm then clears the microwave's top), held down at the end; tried again
    from above at the next of `PRESS_YAWS` while the button is not down."""
    env = sim.env
    psi = approach_yaw(sim)
    tries = iter(PRESS_YAWS)

    def top() -> np.ndarray:
        return sim.point("button:top") + np.array([0.0, 0.0, TIP_DZ])

    def pressed_point() -> np.ndarray:
        with env.working(key):
            p = env.site_at("top", env.target * 1.3)
        return p + np.array([0.0, 0.0, TIP_DZ - 0.004])

    def reached() -> bool:
        return env.reached_part(key)

    def phases() -> list[Phase]:
        yaw = psi + next(tries, PRESS_YAWS[-1])
        return [
            Phase(
                lambda: top() + [0.0, 0.0, 0.08],
                CLOSE,
                tol=0.015,
                steps=100,
                yaw=lambda: yaw,
                pitch=FORWARD_PITCH + PRESS_TILT,
            ),
            Phase(lambda: top() + [0.0, 0.0, 0.01], CLOSE, tol=0.006, steps=50, gain=1.2),
            Phase(pressed_point, CLOSE, tol=None, steps=40, gain=0.5, done=reached),
            Phase(pressed_point, CLOSE, tol=None, steps=6, gain=0.5),  # hold it down
        ]

    return Retry(phases, reached, tries=len(PRESS_YAWS))


def thawing_script(sim: SimEnv) -> list[Phase | Retry]:
    """Open the door, food into the cavity, shut the door, press start."""
    env = sim.env
    psi = approach_yaw(sim)
    subs = sim.spec.subtasks
    door_key = subs[1].joint[6:]
    shut_key = subs[4].joint[6:]
    button_key = subs[5].joint[6:]
    food = subs[2].object
    goal = subs[3].goal
    role = env.role(food)
    home = sim.point("eef")  # the ready pose's grip point (the script is built at reset)
    return [
        *open_door_phases(sim, door_key),
        *swing_wide_phases(sim, door_key),
        # out ahead of the ready pose first: pushing the door wide folds the arm toward
        # its pedestal (link 6 touches it), and straight home it stayed folded
        Phase(lambda: home + CLEAR_AHEAD, OPEN, tol=0.03, steps=50, yaw=lambda: psi),
        Phase(lambda: home + np.array([0.0, 0.0, 0.03]), OPEN, tol=0.03, steps=60),
        forward_pick(sim, food, psi, region_floor_z("counter")),
        *forward_place(
            sim,
            food,
            lambda: sim.point(goal),
            region_floor_z(role.goal),
            psi,
            into=True,
        ),
        *shut_door_phases(sim, shut_key),
        press_button(sim, button_key),
    ]


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {"kitchen_thaw": thawing_script}
