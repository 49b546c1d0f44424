"""Scripted experts for the articulated fixtures: drawer, push button, knob.

Same building blocks as `rover.sim.experts` (waypoint `Phase`s on OSC_POSE): the hand
stays pointing down and turns about z to line its fingers up with the fixture. Targets
are re-read from the simulator every step, so a drawer is pulled along wherever its
slide really points and a knob is followed as it turns.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.motions import CLOSE, OPEN, Phase

LEAD = 0.04  # m (drawer) the pull/push target runs ahead of the handle
TURN_LEAD = 0.35  # rad the hand's yaw runs ahead of the knob while turning
KNOB_DZ = 0.022  # m above the knob's centre the fingers grip it
# m the hand comes down outside the drawer's bar handle (away from the drawer front):
# centred on the bar, the inner finger of the open hand lands on the front's top edge
# and shoves the drawer before the grasp (open by a third, then pushed back)
HANDLE_OUT = 0.008


def latch(sim: SimEnv) -> Callable[[], np.ndarray]:
    """A target frozen at wherever the hand is the first time it is asked for."""
    held: list[np.ndarray] = []

    def point() -> np.ndarray:
        if not held:
            held.append(sim.point("eef"))
        return held[0]

    return point


def _drawer(sim: SimEnv, closing: bool) -> list[Phase]:
    fx = sim.env
    yaw = fx.fixture_yaw() + np.pi / 2  # fingers close across the bar handle

    def handle() -> np.ndarray:
        return sim.point("drawer:handle")

    def outside() -> np.ndarray:  # the descent point, a little out from the bar
        q = fx.joint_value()
        out = fx.site_at("handle", q + 0.01) - fx.site_at("handle", q)
        out[2] = 0.0
        return handle() + HANDLE_OUT * out / max(float(np.linalg.norm(out)), 1e-9)

    def move() -> np.ndarray:
        step = -LEAD if closing else LEAD
        return fx.site_at("handle", fx.joint_value() + step)

    hold, rest = latch(sim), latch(sim)
    return [
        Phase(
            lambda: outside() + np.array([0, 0, 0.08]), OPEN, tol=0.012, steps=80, yaw=lambda: yaw
        ),
        Phase(outside, OPEN, tol=0.006, steps=40, gain=1.5),
        Phase(hold, CLOSE, tol=None, steps=10),
        Phase(move, CLOSE, tol=None, steps=120, gain=0.8, done=lambda: fx.progress() >= 0.97),
        Phase(rest, OPEN, tol=None, steps=8),
        Phase(lambda: rest() + np.array([0.0, 0.0, 0.08]), OPEN, tol=0.015, steps=20),
    ]


def drawer_open_script(sim: SimEnv) -> list[Phase]:
    """Grasp the drawer's bar handle from above and pull along the slide."""
    return _drawer(sim, closing=False)


def drawer_close_script(sim: SimEnv) -> list[Phase]:
    """Grasp the open drawer's handle and push it back in."""
    return _drawer(sim, closing=True)


def button_script(sim: SimEnv) -> list[Phase]:
    """Close the fingers above the button, press it down and hold it there."""
    fx = sim.env

    def top() -> np.ndarray:  # the task's button ("button", a kitchen "stop button")
        return sim.point(f"{fx.part}:top")

    def pressed_point() -> np.ndarray:  # a little below the switching depth
        return fx.site_at("top", fx.target * 1.3) + np.array([0.0, 0.0, -0.004])

    return [
        Phase(lambda: top() + np.array([0, 0, 0.08]), CLOSE, tol=0.012, steps=80),
        Phase(lambda: top() + np.array([0, 0, 0.01]), CLOSE, tol=0.006, steps=40, gain=1.2),
        Phase(pressed_point, CLOSE, tol=None, steps=40, gain=0.5, done=fx.reached),
        Phase(pressed_point, CLOSE, tol=None, steps=6, gain=0.5),  # hold it down
    ]


def knob_script(sim: SimEnv) -> list[Phase]:
    """Grasp the knob from above and turn the wrist a quarter turn with it."""
    fx = sim.env
    yaw0 = fx.fixture_yaw() + np.pi / 2  # fingers across the knob, clear of the lever

    def grip() -> np.ndarray:  # the upper part of the knob: the palm clears its top
        return sim.point("knob") + np.array([0.0, 0.0, KNOB_DZ])

    def turning_yaw() -> float:
        return yaw0 + min(fx.joint_value() + TURN_LEAD, fx.target + 0.15)

    def knob_yaw() -> float:  # let go without turning the knob back
        return yaw0 + fx.joint_value()

    hold, rest = latch(sim), latch(sim)
    return [
        Phase(lambda: grip() + np.array([0, 0, 0.08]), OPEN, tol=0.012, steps=80, yaw=lambda: yaw0),
        Phase(grip, OPEN, tol=0.006, steps=40, gain=1.5),
        Phase(hold, CLOSE, tol=None, steps=10),
        Phase(
            hold,
            CLOSE,
            tol=None,
            steps=120,
            yaw=turning_yaw,
            track_yaw=True,
            done=lambda: fx.progress() >= 0.97,
        ),
        Phase(rest, OPEN, tol=None, steps=8, yaw=knob_yaw, track_yaw=True),
        Phase(lambda: rest() + np.array([0.0, 0.0, 0.08]), OPEN, tol=0.015, steps=20),
    ]


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase]]] = {
    "drawer_open": drawer_open_script,
    "drawer_close": drawer_close_script,
    "button": button_script,
    "knob": knob_script,
}
