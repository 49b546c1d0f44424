"""The forward grasp: take an item from the front, the hand pointing into an opening.

The top-down scripts cannot reach into the microwave's cavity (18 cm high), a cabinet
compartment or under the coffee spout: the Panda's hand and wrist stand about 20 cm
above its fingertips. Here the hand is turned to point horizontally toward the fixture
in use (`FORWARD_PITCH` about world y, then the fixture's yaw about z; the fingers close
horizontally), comes at the item from the front at its own height, closes, lifts it a
few centimetres, carries it level into or out of the opening, lowers it onto the goal
region's floor, lets go and withdraws straight back. `rover.sim.experts.Scripted`
applies the pitch for every script registered in `SCRIPTS`; the phases are ordinary
`rover.sim.motions.Phase`s, targets re-read every step.

The arm starts in a level-hand ready pose (`READY_Q`; `RoverKitchen(level_start=...)`
sets it for every task whose item starts or ends behind an opening): from robosuite's
default hand-down start the controller cannot turn the hand level at counter height.
The pitch is taken from the hand-down frame `HAND_DOWN`, not from the start pose.

How to call it from another script (a composite task, e.g. MicrowaveThawing): the env
needs ``level_start=True``; then ``forward_pick(sim, obj, yaw, floor_z)`` and
``forward_place(sim, obj, goal_point, floor_z, yaw, into=True)`` (``out_of=True`` when
the item starts behind an opening), run by a `Scripted` with ``pitch = FORWARD_PITCH``
and ``down = HAND_DOWN``; ``yaw`` is the fixture's (`approach_yaw`), ``floor_z`` the
region's floor (`region_floor_z`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.kitchen.fixtures import COUNTER_TOP
from rover.sim.kitchen.regions import OPENINGS, REGIONS
from rover.sim.motions import CLOSE, OPEN, Phase, Retry, object_z_range

# the Panda's start pose for the forward-grasp tasks: the hand already level, pointing
# +x, at (-0.25, 0.05, 0.92), behind every counter spot and the fixtures' mouths
# (damped least squares continued from a multi-start bounded least-squares solution;
# every joint 0.30 rad or more inside its limits). From robosuite's default start (hand
# down) the OSC cannot turn the hand level: wrist joint 6 runs into its limit
# (benchmarks/forward_reach.py)
READY_Q = (1.321, 1.065, -0.256, -2.769, -2.0, 1.501, -1.649)
FORWARD_PITCH = -np.pi / 2  # rad about world y: the hand points along +x, fingers along y
# robosuite's Panda grip-site frame at its default start (hand down, fingers closing
# along world y): the frame the pitch and yaw turn from, whatever pose the arm starts in
HAND_DOWN = ((0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0))
PALM_CLEAR = 0.035  # m: the grip point stays this far above a surface (the palm's half height)
STANDOFF = 0.13  # m in front of the item the hand lines up before moving in
DEPTH = 0.008  # m past the item's centre the grip point goes (the item sits between the pads)
LIFT = 0.055  # m the item is lifted before it is carried
MOUTH = 0.2  # m in front of the goal point: outside the opening, where the carry turns in
LOWER = 0.012  # m above the floor the item's bottom is let go
WITHDRAW = 0.16  # m the open hand backs out after letting go


def approach_yaw(sim: SimEnv) -> float:
    """Yaw (rad) of the fixture in use: the hand points along its depth, into it."""
    env = sim.env
    return float(env.scene.layout[env.fixture_name].yaw)


def _ahead(yaw: float) -> np.ndarray:
    return np.array([np.cos(yaw), np.sin(yaw), 0.0])


def region_floor_z(region: str) -> float:
    """World height of a region's floor (the counter top, the cavity floor ...)."""
    return COUNTER_TOP + REGIONS[region].floor


def forward_pick(sim: SimEnv, obj: str, yaw: float, floor_z: float) -> Retry:
    """Line up in front of the item, move in, close, lift; again if the grasp missed."""
    u = _ahead(yaw)

    def grip() -> np.ndarray:
        p = sim.point(obj)
        p[2] = max(p[2], floor_z + PALM_CLEAR)
        return p + DEPTH * u

    def build() -> list[Phase]:
        hold: list[np.ndarray] = []

        def freeze() -> np.ndarray:
            if not hold:
                hold.append(sim.point("eef"))
            return hold[0]

        return [
            Phase(lambda: grip() - STANDOFF * u + [0, 0, 0.08], OPEN, 0.03, 100, yaw=lambda: yaw),
            Phase(lambda: grip() - STANDOFF * u, OPEN, tol=0.012, steps=60),
            Phase(grip, OPEN, tol=0.006, steps=50),
            Phase(freeze, CLOSE, tol=None, steps=10),
            Phase(lambda: freeze() + [0, 0, LIFT], CLOSE, tol=0.01, steps=40, gain=0.6),
        ]

    return Retry(build, lambda: sim.predicate(f"lifted:{obj}"))


def forward_place(
    sim: SimEnv,
    obj: str,
    goal: Callable[[], np.ndarray],
    floor_z: float,
    yaw: float,
    into: bool,
    out_of: bool = False,
) -> list[Phase]:
    """Carry the held item level to `goal()` (x, y), lower it onto `floor_z`, let go, back out.

    `into`: the goal is behind an opening (line up `MOUTH` in front of it, then move in);
    `out_of`: the item starts behind one (back out far enough to clear it first).
    """
    u = _ahead(yaw)

    def hang() -> float:  # how far the held item reaches below the grip point
        return float(np.clip(sim.point("eef")[2] - object_z_range(sim, obj)[0], 0.0, 0.2))

    def carry_z() -> float:
        return floor_z + 0.03 + hang()

    start: list[np.ndarray] = []

    def back() -> np.ndarray:
        if not start:
            start.append(sim.point("eef"))
        return start[0] - (MOUTH + 0.02 if out_of else 0.1) * u

    def at(offset: float, z: Callable[[], float]) -> Callable[[], np.ndarray]:
        def target() -> np.ndarray:
            g = goal() - offset * u
            return np.array([g[0], g[1], z()])

        return target

    rest: list[np.ndarray] = []

    def freeze() -> np.ndarray:
        if not rest:
            rest.append(sim.point("eef"))
        return rest[0]

    line_up = MOUTH if into else 0.1
    return [
        Phase(back, CLOSE, tol=0.02, steps=60, gain=0.8),
        Phase(at(line_up, carry_z), CLOSE, tol=0.02, steps=120, gain=0.8),
        Phase(at(0.0, carry_z), CLOSE, tol=0.012, steps=80, gain=0.6),
        Phase(at(0.0, lambda: floor_z + LOWER + hang()), CLOSE, tol=0.008, steps=40, gain=0.6),
        Phase(freeze, OPEN, tol=None, steps=10),
        Phase(lambda: freeze() - WITHDRAW * u, OPEN, tol=0.02, steps=50),
        Phase(lambda: freeze() - WITHDRAW * u + [0, 0, 0.06], OPEN, tol=0.02, steps=30),
    ]


def forward_pick_place_script(sim: SimEnv) -> list[Phase | Retry]:
    """A kitchen pick-and-place task whose start or goal is behind an opening."""
    env = sim.env
    grasp, move = sim.spec.subtasks
    obj = grasp.object
    yaw = approach_yaw(sim)
    return [
        forward_pick(sim, obj, yaw, region_floor_z(env.item_start)),
        *forward_place(
            sim,
            obj,
            lambda: sim.point(move.goal),
            region_floor_z(env.item_goal),
            yaw,
            into=env.item_goal in OPENINGS,
            out_of=env.item_start in OPENINGS,
        ),
    ]


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {
    "kitchen_forward": forward_pick_place_script,
}
