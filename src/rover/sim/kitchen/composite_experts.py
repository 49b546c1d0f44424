"""Chained scripted experts of the kitchen composite tasks.

A composite task's expert is its atomic tasks' experts run one after the other, from
one recorded demonstration: for each (pick up, place) pair of subtasks, back to the
start pose (after the first), the tabletop top-down pick (`rover.sim.motions`) and the
carry-and-lower placement. Two things differ from the tabletop pick-and-place script:

* the grasp height follows the drawn instance: the Panda's fingers are about 5 cm long,
  so an item taller than that grasped at its centre (a 12 cm cucumber standing up)
  meets the palm on its top and is pushed over; the fingers close `TOP_MARGIN` below
  its top instead;
* the item is lowered to `DROP_DZ` above the goal surface before it is let go, so a
  round item set on the cutting board does not bounce or roll off it.
"""

from __future__ import annotations

from collections.abc import Callable

from rover.sim.env import SimEnv
from rover.sim.motions import OPEN, Phase, Retry, object_z_range, pick_retry, place_phases

TOP_MARGIN = 0.045  # m below an item's top the fingers close (palm clear of it)
DROP_DZ = 0.012  # m above the goal surface the item's bottom is let go


def grasp_dz(sim: SimEnv, obj: str) -> float:
    """Height above the item's centre to grasp it: its centre, or `TOP_MARGIN` below
    its top when that is higher (a tall item)."""
    top = object_z_range(sim, obj)[1]
    return float(max(0.0, top - TOP_MARGIN - sim.point(obj)[2]))


def chained_pick_place(sim: SimEnv) -> list[Phase | Retry]:
    """Pick and place each item of the task in turn, the hand back home between."""
    phases: list[Phase | Retry] = []
    subs = sim.spec.subtasks
    home = sim.point("eef")
    for k, (grasp, move) in enumerate(zip(subs[0::2], subs[1::2], strict=True)):
        obj = grasp.object
        if k:  # back to the start pose first, as the tabletop pick-and-place script does
            phases.append(Phase(lambda: home, OPEN, tol=0.03, steps=60))
        phases.append(pick_retry(sim, obj, None, grasp_dz(sim, obj)))
        carry = float(sim.point(move.goal)[2]) + 0.20
        phases += place_phases(sim, move.goal, DROP_DZ, carry, obj=obj)
    return phases


SCRIPTS: dict[str, Callable[[SimEnv], list[Phase | Retry]]] = {
    "kitchen_chain": chained_pick_place,
}
