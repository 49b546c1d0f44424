"""Scripted experts for kitchen parts the tabletop scripts do not cover.

Built like `rover.sim.experts_articulated` (waypoint `Phase`s, targets re-read every
step): `turn_script` grips a dial (stove knob, faucet handle) and turns it toward its
target in either direction (on or off); `swing_script` grasps a part on a vertical hinge
(a cabinet door's bar handle, the sink spout's arm) and walks it along its arc, the
hand turning with it. Both pick, of the two finger yaws that grip the same way (the
grip is symmetric under a half turn), the one whose motion stays nearest the hand's
start yaw, so the wrist never runs into its joint limit.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.experts_articulated import latch
from rover.sim.kitchen.composite_experts import SCRIPTS as COMPOSITE_SCRIPTS
from rover.sim.motions import CLOSE, OPEN, Phase, wrap_angle

TURN_LEAD = 0.35  # rad the hand's yaw runs ahead of a dial while turning it
SWING_LEAD = 0.12  # rad along the arc the pull target runs ahead of a hinged part
GRIP_DZ = 0.022  # m above a dial's centre the fingers grip it
# yaw (fixture frame, part at joint 0) at which the fingers close across the grasp point
GRIP_YAW = {"knob": np.pi / 2, "door": np.pi / 2, "spout": 0.0}
SWING_SITE = {"door": "handle", "spout": "tip"}


def _base_yaw(fx) -> float:
    """Yaw of the grip at joint 0, of the two symmetric ones the one nearest the start."""
    base = fx.fixture_yaw() + GRIP_YAW[fx.kind]
    mid = (fx.start_q + fx.target) / 2
    options = [wrap_angle(base, 2 * np.pi), wrap_angle(base + np.pi, 2 * np.pi)]
    return min(options, key=lambda b: abs(wrap_angle(b + mid, 2 * np.pi)))


def _direction(fx) -> float:
    return 1.0 if fx.target >= fx.start_q else -1.0


def _ahead(fx, lead: float) -> float:
    """The joint value `lead` rad ahead of the part, never past the target by > 0.15."""
    sign = _direction(fx)
    q = fx.joint_value() + sign * lead
    end = fx.target + sign * 0.15
    return min(q, end) if sign > 0 else max(q, end)


def _grasp(
    target: Callable[[], np.ndarray], hold: Callable[[], np.ndarray], start_yaw: float
) -> list[Phase]:
    """Come down on a part's grip point from 8 cm above, the wrist at the part's start yaw,
    and close on it (both the dial and the swing experts begin this way)."""
    return [
        Phase(
            lambda: target() + np.array([0, 0, 0.08]),
            OPEN,
            tol=0.012,
            steps=80,
            yaw=lambda: start_yaw,
        ),
        Phase(target, OPEN, tol=0.006, steps=40, gain=1.5),
        Phase(hold, CLOSE, tol=None, steps=10),
    ]


def _finish(rest: Callable[[], np.ndarray], yaw: Callable[[], float]) -> list[Phase]:
    return [
        Phase(rest, OPEN, tol=None, steps=8, yaw=yaw, track_yaw=True),
        Phase(lambda: rest() + np.array([0.0, 0.0, 0.08]), OPEN, tol=0.015, steps=20),
    ]


def turn_script(sim: SimEnv) -> list[Phase]:
    """Grip a dial from above and turn the wrist with it, toward its target."""
    fx = sim.env
    base = _base_yaw(fx)
    name = fx.part

    def grip() -> np.ndarray:
        return sim.point(name) + np.array([0.0, 0.0, GRIP_DZ])

    def knob_yaw() -> float:
        return base + fx.joint_value()

    hold, rest = latch(sim), latch(sim)
    return [
        *_grasp(grip, hold, knob_yaw()),
        Phase(
            hold,
            CLOSE,
            tol=None,
            steps=120,
            yaw=lambda: base + _ahead(fx, TURN_LEAD),
            track_yaw=True,
            done=lambda: fx.progress() >= 0.97,
        ),
        *_finish(rest, knob_yaw),
    ]


def swing_script(sim: SimEnv) -> list[Phase]:
    """Grasp a hinged part's handle from above and carry it along its arc."""
    fx = sim.env
    base = _base_yaw(fx)
    site = SWING_SITE[fx.kind]
    point = f"{fx.part}:{site}"  # the task object is named as the facts name the part

    def part_yaw() -> float:
        return base + fx.joint_value()

    def handle() -> np.ndarray:
        return sim.point(point)

    def along() -> np.ndarray:
        return fx.site_at(site, _ahead(fx, SWING_LEAD))

    hold, rest, start = latch(sim), latch(sim), latch(sim)
    # the sink spout's arm reaches out over the basin toward the hand's start pose: rise
    # above it first, or the hand sweeps it round on the way to its grip point
    clear = [Phase(lambda: start() + np.array([0.0, 0.0, 0.1]), OPEN, tol=0.02, steps=30)]
    return [
        *(clear if fx.kind == "spout" else []),
        *_grasp(handle, hold, part_yaw()),
        Phase(
            along,
            CLOSE,
            tol=None,
            steps=160,
            gain=0.8,
            yaw=lambda: base + _ahead(fx, SWING_LEAD),
            track_yaw=True,
            done=lambda: fx.progress() >= 0.97,
        ),
        *_finish(rest, part_yaw),
    ]


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase]]] = {
    "kitchen_turn": turn_script,
    "kitchen_swing": swing_script,
}
SCRIPTS.update(COMPOSITE_SCRIPTS)  # chained experts of the composite tasks
