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
   (`Phase.pitch`) above the button, as the button task's expert presses it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.experts_articulated import latch
from rover.sim.kitchen.forward_grasp import (
    approach_yaw,
    forward_pick,
    forward_place,
    region_floor_z,
)
from rover.sim.motions import CLOSE, OPEN, Phase, Retry

ALONG_BAR = float(-np.pi / 2)  # rad from the door's inward normal to the hand's heading
# m the grip point sits from the handle's centre toward the door's free edge: the hand,
# pointing along the bar toward the hinge, has its palm face 4.1 cm behind the grip
# point, and the bar's end cap reaches 4.05 cm from its centre
BAR_OUT = 0.008
BAR_DZ = -0.002  # m: the grip point this far below the bar's centre line
PULL_LEAD = 0.15  # rad along the arc the pull target runs ahead of the door
PUSH_LEAD = 0.15  # rad ... and the push target while shutting it
FACE_DOWN = 0.07  # m below the handle the fingertips push the door's face
FACE_OUT = 0.065  # m out from the handle's centre line to the door's face (bar at 7 cm)
PRESS_ABOVE = 0.1  # m above the button the hand turns down


def _inward(yaw: float) -> np.ndarray:
    return np.array([np.cos(yaw), np.sin(yaw), 0.0])


def open_door_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Grasp the handle's bar from above and carry it along the door's arc."""
    env = sim.env
    psi = approach_yaw(sim)

    def door_q() -> float:
        with env.working(key):
            return env.joint_value()

    def grip_yaw() -> float:  # the hand along the bar, its fingers across it
        return psi + door_q() + ALONG_BAR

    def on_bar(p: np.ndarray, q: float) -> np.ndarray:  # toward the door's free edge
        return p + BAR_OUT * _inward(psi + q + np.pi / 2) + np.array([0.0, 0.0, BAR_DZ])

    def handle() -> np.ndarray:
        return on_bar(sim.point("microwave door:handle"), door_q())

    def ahead() -> np.ndarray:
        with env.working(key):
            q = min(env.joint_value() + PULL_LEAD, env.target + 0.1)
            return on_bar(env.site_at("handle", q), q)

    def done() -> bool:
        with env.working(key):
            return env.progress() >= 0.97

    hold = latch(sim)
    return [
        Phase(lambda: handle() + [0.0, 0.0, 0.08], OPEN, tol=0.012, steps=120, yaw=grip_yaw),
        Phase(handle, OPEN, tol=0.006, steps=50, gain=1.2),
        Phase(hold, CLOSE, tol=None, steps=10),
        Phase(ahead, CLOSE, tol=None, steps=220, gain=0.8, yaw=grip_yaw, track_yaw=True, done=done),
    ]


def leave_door_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Back the fingers out of the handle's gap and rise clear of the bar."""
    env = sim.env
    psi = approach_yaw(sim)
    rest = latch(sim)

    def out() -> np.ndarray:
        with env.working(key):
            q = env.joint_value()
        return rest() - 0.09 * _inward(psi + q) + np.array([0.0, 0.0, 0.02])

    return [Phase(out, CLOSE, tol=0.02, steps=40)]


def shut_door_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Push the door shut from outside: fingertips on its face under the handle."""
    env = sim.env
    psi = approach_yaw(sim)

    def door_yaw() -> float:
        with env.working(key):
            return psi + env.joint_value()

    def face(q_back: float = 0.0) -> np.ndarray:
        with env.working(key):
            q = max(env.joint_value() - q_back, -0.05)
            p = env.site_at("handle", q)
        return p + FACE_OUT * _inward(psi + q) - np.array([0.0, 0.0, FACE_DOWN])

    def done() -> bool:
        with env.working(key):
            return env.progress() >= 0.98

    stand = lambda: face() - 0.08 * _inward(door_yaw())  # noqa: E731
    return [
        Phase(stand, CLOSE, tol=0.015, steps=120, yaw=door_yaw),
        Phase(lambda: face() - 0.01 * _inward(door_yaw()), CLOSE, tol=0.01, steps=40),
        Phase(
            lambda: face(PUSH_LEAD),
            CLOSE,
            tol=None,
            steps=200,
            gain=0.8,
            yaw=door_yaw,
            track_yaw=True,
            done=done,
        ),
        Phase(lambda: face(0.0) - 0.1 * _inward(door_yaw()), CLOSE, tol=0.02, steps=40),
    ]


def press_button_phases(sim: SimEnv, key: str) -> list[Phase]:
    """Turn the hand down above the start button and press it, held down at the end."""
    env = sim.env
    psi = approach_yaw(sim)

    def top() -> np.ndarray:
        return sim.point("button:top")

    def pressed_point() -> np.ndarray:
        with env.working(key):
            return env.site_at("top", env.target * 1.3) + np.array([0.0, 0.0, -0.004])

    def reached() -> bool:
        return env.reached_part(key)

    above = np.array([0.0, 0.0, PRESS_ABOVE])
    return [
        Phase(lambda: top() + above, CLOSE, tol=0.02, steps=80, yaw=lambda: psi),
        Phase(lambda: top() + above, CLOSE, tol=0.015, steps=80, pitch=0.0),
        Phase(lambda: top() + np.array([0, 0, 0.01]), CLOSE, tol=0.006, steps=50, gain=1.2),
        Phase(pressed_point, CLOSE, tol=None, steps=40, gain=0.5, done=reached),
        Phase(pressed_point, CLOSE, tol=None, steps=6, gain=0.5),  # hold it down
    ]


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
    home = latch(sim)
    return [
        *open_door_phases(sim, door_key),
        *leave_door_phases(sim, door_key),
        Phase(
            lambda: home() + np.array([0.0, 0.0, 0.03]), OPEN, tol=0.03, steps=80, yaw=lambda: psi
        ),
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
        *press_button_phases(sim, button_key),
    ]


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {"kitchen_thaw": thawing_script}
