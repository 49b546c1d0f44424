"""The chained forward-grasp expert of RestockPantry and PrepareCoffee.

For each (pick up, place) pair of subtasks: `forward_grasp.forward_pick` from the
counter and `forward_grasp.forward_place` into the goal region (both with the hand level,
pointing into the fixture in use), then back to the level-hand start point before the
next pair (the hand stays level: robosuite's hand-down start cannot be turned level at
counter height, `forward_grasp`'s docstring). A (reach, press) pair on the fixture's
button is `press_phases`: the closed hand, turned half-way down, presses it.

Registered as ``kitchen_forward_chain``; `rover.sim.experts` runs it with the forward
grasp's pitch (the hand level) like ``kitchen_forward``.
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
from rover.sim.kitchen.regions import OPENINGS
from rover.sim.motions import CLOSE, OPEN, Phase, Retry

PRESS_ABOVE = 0.08  # m above the button's top the fingertips line up
# the hand's pitch while pressing (rad about world y: -pi/2 level, 0 pointing down),
# half-way down: the fingertips are its lowest point. Level, the palm's underside met
# the machine's head before the button was 1 cm down (and the fingers, which the touch
# and press facts read, never touched it); turned fully down above the button, joint 6
# reached its limit and the hand stopped 13 cm short; at -1.0 the fingertips slid off
PRESS_PITCH = -0.8
# rad added to the fixture's yaw while pressing (a round button: the yaw is free); at the
# fixture's own yaw wrist joint 7 reached its limit on the way up in 2 of 8 seeds
PRESS_YAW = -0.3
RETRY_YAWS = (PRESS_YAW, PRESS_YAW - 0.3, PRESS_YAW + 0.3)  # rad, one per try


def press_retry(sim: SimEnv, yaw: float) -> Retry:
    """`press_phases` until the button is down at the end, the hand's yaw offset changed
    each try (`RETRY_YAWS`): in 2 of 20 seeds the first press touched the button without
    pushing it past its switching depth."""
    tried: list[float] = []

    def build() -> list[Phase]:
        tried.append(RETRY_YAWS[min(len(tried), len(RETRY_YAWS) - 1)])
        return press_phases(sim, yaw, tried[-1])

    return Retry(build, sim.env.reached)


def press_phases(sim: SimEnv, yaw: float, offset: float = 0.0) -> list[Phase]:
    """Rise straight up turning the closed hand half-way down (`Phase.pitch`), come over
    the button and press it past its switching depth with the fingertips, as the button
    task's expert does; held down at the end (a spring button rises again when let go)."""
    fx = sim.env

    def top() -> np.ndarray:
        return sim.point("button:top")

    def pressed() -> np.ndarray:  # a little below the switching depth (the tabletop rule)
        return fx.site_at("top", fx.target * 1.3) + np.array([0.0, 0.0, -0.004])

    above = np.array([0.0, 0.0, PRESS_ABOVE])
    start = latch(sim)

    def raised() -> np.ndarray:  # straight up from where the hand is, to the button's height
        return np.array([*start()[:2], top()[2] + PRESS_ABOVE])

    return [
        Phase(raised, CLOSE, tol=0.02, steps=80, yaw=lambda: yaw + offset, pitch=PRESS_PITCH),
        Phase(lambda: top() + above, CLOSE, tol=0.012, steps=100),
        Phase(lambda: top() + np.array([0, 0, 0.01]), CLOSE, tol=0.006, steps=50, gain=1.2),
        Phase(pressed, CLOSE, tol=None, steps=40, gain=0.5, done=fx.reached),
        Phase(pressed, CLOSE, tol=None, steps=6, gain=0.5),  # hold it down
    ]


def forward_chain(sim: SimEnv) -> list[Phase | Retry]:
    """Each item in turn with the forward grasp, home between; then the button, if any."""
    env = sim.env
    yaw = approach_yaw(sim)
    home = sim.point("eef")
    phases: list[Phase | Retry] = []
    subs = sim.spec.subtasks
    for k, (first, second) in enumerate(zip(subs[0::2], subs[1::2], strict=True)):
        if k:  # back to the level-hand start point, still pointing into the fixture
            phases.append(Phase(lambda: home, OPEN, tol=0.03, steps=60, yaw=lambda: yaw))
        if not sim.spec.object_spec(first.object).graspable:  # the fixture's button
            phases.append(press_retry(sim, yaw))
            continue
        obj = first.object
        goal = env.role(obj).goal
        phases.append(forward_pick(sim, obj, yaw, region_floor_z("counter")))
        phases += forward_place(
            sim,
            obj,
            lambda g=second.goal: sim.point(g),
            region_floor_z(goal),
            yaw,
            into=goal in OPENINGS,
        )
    return phases


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {
    "kitchen_forward_chain": forward_chain,
}
