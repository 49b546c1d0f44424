"""Chained scripted experts of the kitchen composite tasks.

A composite task's expert is its atomic tasks' experts run one after the other, from
one recorded demonstration: for each (pick up, place) pair of subtasks, back to the
start pose (after the first), the tabletop top-down pick (`rover.sim.motions`) and the
carry-and-lower placement. Where they differ from the tabletop pick-and-place script:

* the grasp height follows the drawn instance: the Panda's fingers are about 5 cm long,
  so an item taller than that grasped at its centre (a 12 cm cucumber standing up)
  meets the palm on its top and is pushed over; the fingers close `TOP_MARGIN` below
  its top instead;
* the item is lowered to `DROP_DZ` above the goal surface before it is let go, so a
  round item set on the cutting board does not bounce or roll off it;
* a box set into a pan (the sponge) is let go `BOX_DROP_DZ` above the pan's floor and
  lowered at `DOWN_GAIN`: lowered fast to the item's own height the hand overshot, the
  sponge jammed between a finger and the pan's wall, and the hand lifted the pan;
* an item taken by a handle (the pan) is carried so that its centre, not the hand,
  comes over the goal, at `PAN_CARRY` above it: low enough for the pan's rim to pass
  under the sink spout's nozzle, high enough for its bottom to clear the basin's walls.

A pair of subtasks on a fixture part (grasp the sink handle, turn it) is the faucet
task's own expert (`rover.sim.kitchen.experts.turn_script`), after going home, run again
(up to three tries in all) while the part is not turned.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial

import numpy as np

from rover.sim.env import SimEnv
from rover.sim.motions import (
    CLOSE,
    OPEN,
    Phase,
    Retry,
    object_bottom,
    object_z_range,
    pick_phases,
    pick_retry,
    place_phases,
)

TOP_MARGIN = 0.045  # m below an item's top the fingers close (palm clear of it)
DROP_DZ = 0.012  # m above the goal surface the item's bottom is let go
BOX_DROP_DZ = 0.03  # m: a box (a sponge) is let go higher, its fingers clear of the pan
DOWN_GAIN = 0.6  # lowering gain of a box set into a pan (the tabletop script's is 1.0)
PAN_CARRY = 0.16  # m above the goal point the hand carries an item held by its handle
# rad the Panda's last joint starts from the middle of its range (pi/4 of +-2.9): the
# hand's yaw that leaves it centred is the base joint's turn plus this
WRIST_START = float(np.pi / 4)
HANDLE_DZ = -0.008  # m: the grip point sits this far below a handle's centre line (the
# finger pads' centre is above the grip site: closed at the site, they met above a 14 mm
# thick handle)


def grasp_dz(sim: SimEnv, obj: str) -> float:
    """Height above the item's centre to grasp it: its centre, or `TOP_MARGIN` below
    its top when that is higher (a tall item)."""
    top = object_z_range(sim, obj)[1]
    return float(max(0.0, top - TOP_MARGIN - sim.point(obj)[2]))


def held_place_phases(sim: SimEnv, goal: str, obj: str, drop_dz: float) -> list[Phase]:
    """Carry an item held off its centre (a pan by its handle) so that its centre comes
    over `goal`, lower its bottom to `drop_dz` above the goal point, release, retreat."""

    def offset() -> np.ndarray:  # hand minus item centre, horizontal
        d = sim.point("eef") - sim.point(obj)
        d[2] = 0.0
        return d

    def reach() -> float:  # how far the item hangs below the grip point
        return float(np.clip(sim.point("eef")[2] - object_bottom(sim, obj), 0.0, 0.2))

    def over() -> np.ndarray:
        g = sim.point(goal) + offset()
        return np.array([g[0], g[1], sim.point(goal)[2] + PAN_CARRY])

    def rise() -> np.ndarray:
        e = sim.point("eef")
        return np.array([e[0], e[1], over()[2]])

    def down() -> np.ndarray:
        return sim.point(goal) + offset() + np.array([0, 0, drop_dz + reach()])

    rest: list[np.ndarray] = []

    def freeze() -> np.ndarray:
        if not rest:
            rest.append(sim.point("eef"))
        return rest[0]

    return [
        Phase(rise, CLOSE, tol=0.02, steps=40, gain=0.6),
        Phase(over, CLOSE, tol=0.02, steps=120, gain=0.6),
        Phase(down, CLOSE, tol=0.01, steps=60, gain=0.6),
        Phase(freeze, OPEN, tol=None, steps=8),
        Phase(lambda: freeze() + np.array([0, 0, 0.08]), OPEN, tol=0.02, steps=20),
    ]


def base_turn(sim: SimEnv, p: np.ndarray) -> float:
    """The arm's base-joint turn toward point `p` (rad about z, 0 straight ahead)."""
    base = sim.data.xpos[sim._body_id(sim.env.robots[0].robot_model.root_body)]
    return float(np.arctan2(p[1] - base[1], p[0] - base[0]))


def turned_pick(
    sim: SimEnv,
    obj: str,
    goal: str,
    period: float,
    dz: float = 0.0,
    point: str | None = None,
    chosen: list[float] | None = None,
) -> Retry:
    """Pick an item whose grasp has a symmetry (`period`: a handle or a box, a half
    turn) at the symmetric yaw that leaves the wrist's last joint the most room both at
    the item and over its goal.

    Reaching sideways turns the arm's base joint and the hand with it, so the yaw the
    last joint needs no turn for is the base joint's; that joint starts `WRIST_START`
    from the middle of its range. The yaw nearest the base turns at the grasp and at the
    goal, moved by that offset, keeps the joint inside its range at both ends: a pan
    handle taken at -pi/2 ran it into its limit 2.6 cm short of the handle, a sponge
    taken at a yaw far from the carry's left the arm folded against joint 6's limit.
    With `chosen` the carry turns the hand with the base (`carry_turned`), so only the
    grasp's end counts, and the yaw taken is appended to it; the grasp then starts from
    home (yaw 0) and takes the symmetric yaw between 0 and the centred one (or the
    nearest to that range): the one nearest the centred yaw could be a half turn from
    home, and turning that far at the sponge rolled the wrist over (joint 5 near 2.4
    rad, joint 6 at its limit), after which the faucet lever was out of reach."""

    def phases() -> list[Phase]:
        out = pick_phases(sim, obj, period, dz, point)
        at = base_turn(sim, sim.point(point or obj))
        want = at if chosen is not None else (at + base_turn(sim, sim.point(goal))) / 2
        want += WRIST_START
        yaw = out[0].yaw()
        options = [yaw + k * period for k in (-2, -1, 0, 1, 2)]
        if chosen is None:
            best = min(options, key=lambda y: abs(y - want))
        else:  # from home (the start yaw, 0): turn toward `want`, never past it
            lo, hi = min(0.0, want), max(0.0, want)
            best = min(options, key=lambda y: (max(lo - y, y - hi, 0.0), abs(y - want)))
        out[0].yaw = lambda: best
        if chosen is not None:
            chosen[:] = [best, at]
        return out

    return Retry(phases, lambda: sim.predicate(f"lifted:{obj}"))


def chained_pick_place(sim: SimEnv) -> list[Phase | Retry]:
    """Pick and place each item of the task in turn, the hand back home between; a
    fixture part's pair of subtasks (grasp, turn) with the faucet task's expert."""
    from rover.sim.kitchen.experts import turn_script  # it imports this module

    phases: list[Phase | Retry] = []
    subs = sim.spec.subtasks
    home = sim.point("eef")
    turned = False  # the last grasp took a yaw by its symmetry (a handle, a box)
    for k, (grasp, move) in enumerate(zip(subs[0::2], subs[1::2], strict=True)):
        obj = grasp.object
        if k:  # back to the start pose first, as the tabletop pick-and-place script does;
            # after a turned grasp with the wrist unwound: a pan carried at a quarter turn
            # left it where the next grasp's turn ran joint 6 into its limit
            unwind = (lambda: 0.0) if turned else None
            phases.append(Phase(lambda: home, OPEN, tol=0.03, steps=60, yaw=unwind))
        if not sim.spec.object_spec(obj).graspable:  # the fixture part the task works:
            # the dial expert, tried again from above the part if the part is not turned
            phases.append(Retry(lambda: turn_script(sim), partial(sim.predicate, f"turned:{obj}")))
            continue
        point = grasp.object_points[0] if grasp.object_points[0] != obj else None
        turned = point is not None or grasp_period(sim, obj) is not None
        if point is not None:  # taken by a handle: fingers across the handle's width
            phases.append(turned_pick(sim, obj, move.goal, np.pi, HANDLE_DZ, point))
            phases += held_place_phases(sim, move.goal, obj, DROP_DZ)
            continue
        period = grasp_period(sim, obj)
        carry = float(sim.point(move.goal)[2]) + 0.20
        if period is None:
            phases.append(pick_retry(sim, obj, None, grasp_dz(sim, obj)))
            phases += place_phases(sim, move.goal, DROP_DZ, carry, obj=obj)
            continue
        chosen: list[float] = []  # a box (a sponge): the hand turns with the arm's base
        phases.append(turned_pick(sim, obj, move.goal, period, grasp_dz(sim, obj), None, chosen))
        placing = place_phases(sim, move.goal, BOX_DROP_DZ, carry, obj=obj)
        phases += carry_turned(sim, placing, chosen)
    return phases


def carry_turned(sim: SimEnv, phases: list[Phase], chosen: list[float]) -> list[Phase]:
    """The carry, lowering and release of `place_phases` with the hand's yaw following
    the arm's base turn from the grasp (`chosen`: yaw taken, base turn there), so the
    wrist's last joint stays where the grasp left it: carried at a fixed yaw from the
    counter's far side to the sink, the sponge folded the wrist against joint 6's limit
    and the faucet lever was then out of reach."""

    def yaw() -> float:
        taken, at = chosen
        return taken + base_turn(sim, sim.point("eef")) - at

    for ph in phases[:4]:  # rise, over, down, let go; the retreat keeps the last yaw
        ph.yaw, ph.track_yaw = yaw, True
    # lowered at full gain the hand overshot into the pan and, opening there, hooked the
    # pan's wall and lifted the pan out of the sink
    phases[2].gain = DOWN_GAIN
    return phases


def grasp_period(sim: SimEnv, obj: str) -> float | None:
    """Grasp symmetry of the item's drawn instance: a box (a sponge) is taken across its
    narrow faces (half-turn symmetry), anything round at the clearest yaw (None)."""
    from rover.sim.kitchen.objects import CATALOGUE

    drawn = next((o["name"] for o in sim.env.scene.objects if o["role"] == obj), None)
    shape = next((i.shape for i in CATALOGUE if i.name == drawn), None)
    return np.pi if shape == "box" else None


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {
    "kitchen_chain": chained_pick_place,
}
