"""What a composite kitchen scene holds besides the fixtures: item roles, a cutting board.

An `ItemRole` is one named free item of a composite task (the first vegetable: a
vegetable, starting on a counter spot, going onto the board).

The board is a thin wooden slab welded to the counter (it is a place, not something the
robot moves) with two goal spots on its top, one per vegetable of ArrangeVegetables, so
the second vegetable is set down beside the first rather than on it. `BOARD_REGION`
says where an item rests "on" it, in the board's own frame, as the fixture regions of
`rover.sim.kitchen.regions` do. Pure data, plus `build_board` (robosuite, imported late).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rover.sim.kitchen.regions import SETTLE

BOARD_HALF = (0.095, 0.13, 0.007)  # m: half depth (x), half length (y), half thickness
BOARD_RGBA = (0.72, 0.52, 0.3, 1.0)  # light wood
BOARD_BODY = "board_main"  # robosuite BoxObject named "board": body "board_main"
# goal sites (board frame) on the centre line, 11 cm apart: an upright carrot let go on
# the board tips over, toward or away from the robot, and its centre lands up to 6 cm
# from where it stood, still on the board
BOARD_SPOTS = {"board_spot_1": (0.0, 0.055), "board_spot_2": (0.0, -0.055)}
# where the board's centre is drawn (counter frame) and its yaw
BOARD_X = (-0.12, -0.09)
BOARD_Y = (0.14, 0.18)
BOARD_YAW = (-0.2, 0.2)


@dataclass(frozen=True)
class SlabRegion:
    """Where an item rests on a slab: its centre within `half` of the slab's centre
    (slab frame), its lowest point between 1 cm below the top and `SETTLE` above it."""

    name: str
    half: tuple[float, float]
    top: float  # height of the resting surface above the slab's centre

    def holds(self, local_centre, local_bottom: float) -> bool:
        return bool(
            abs(local_centre[0]) <= self.half[0]
            and abs(local_centre[1]) <= self.half[1]
            and self.top - 0.01 <= local_bottom <= self.top + SETTLE
        )


# an item "on" the board: its centre over the board (a vegetable's centre past the edge
# would tip it off) and resting on the top face
BOARD_REGION = SlabRegion("cutting board", (BOARD_HALF[0], BOARD_HALF[1]), BOARD_HALF[2])


@dataclass(frozen=True)
class ItemRole:
    """One named item of a composite task: what it is, where it starts, where it goes.

    ``start`` is a counter spot name of `START_SPOTS`; ``goal`` the region its facts
    report when it is done ("cutting board", "sink", ...)."""

    name: str  # the task object's name ("first vegetable")
    category: str  # catalogue category ("vegetable")
    start: str
    goal: str

    @property
    def prefix(self) -> str:
        return "c" + self.name.replace(" ", "_") + "_"


def item_body(role: ItemRole) -> str:
    """The MuJoCo body of an item role (pure naming: task specs use it)."""
    from rover.sim.kitchen.items import host_body

    return host_body(role.category, role.prefix)


# counter spots items start on (counter frame x range, y range): in front of the
# cabinet, on the side away from the cutting board, far enough apart for the fingers
START_SPOTS = {
    "counter far": ((-0.15, -0.07), (-0.27, -0.2)),
    "counter near": ((-0.15, -0.07), (-0.1, -0.06)),
    # PreSoakPan (the sink in reach on the robot's right, y < 0.13 with its footprint):
    # the pan beside it, the sponge in front of the pan's handle, out of the pan's way
    # and 0.4-0.5 m from the arm's base (at 0.33 m, lifting it folded the elbow against
    # its limit and the wrist rolled over: the faucet lever was then out of reach)
    "counter beside sink": ((-0.1, -0.05), (0.24, 0.28)),
    "counter front": ((-0.3, -0.25), (0.32, 0.38)),
}
# spots measured from the fixture in use (x: counter frame; y: from the fixture's +y
# edge along the counter), for fixtures drawn in a range of places: the forward-grasp
# composites (RestockPantry, PrepareCoffee) take items from beside the cabinet or the
# coffee machine, on its +y side as the pick-and-place tasks do (`regions.COUNTER_SIDE`)
BESIDE_SPOTS = {
    # beside the coffee machine at CoffeeSetupMug's gap (`regions.COUNTER_GAP`), further
    # from the robot than its `regions.COUNTER_X`: with the spot 10-14 cm in front of the
    # counter's centre line the level hand's stand-off point, 13 cm nearer the robot
    # still, was out of reach (joint 4 near its limit) and the hand came down on the mug
    # and pushed it away (PrepareCoffee seeds 5 and 14 of 20)
    "beside fixture": ((-0.08, -0.03), (0.09, 0.15)),
    # two items one behind the other: the front one is taken first, so the hand never
    # reaches past an item to get the other (nearer the robot than x -0.13 the level
    # hand's stand-off point is out of reach: it stopped 10 cm high, came down on the
    # item and pushed it away)
    "beside fixture front": ((-0.13, -0.1), (0.09, 0.14)),
    "beside fixture back": ((-0.03, -0.01), (0.09, 0.14)),
}
# the start yaw range of an item per spot (default: any): the pan's handle points along
# the counter, away from the sink, so it stays along the basin's length when set in it
START_YAW = {"counter beside sink": (float(np.pi / 2 - 0.2), float(np.pi / 2 + 0.2))}


def build_board():
    """The board as a static robosuite box with its goal spot sites on top."""
    import xml.etree.ElementTree as ET

    from robosuite.models.objects import BoxObject

    from rover.sim.kitchen.objects import make_static

    board = BoxObject(
        "board",
        size=list(BOARD_HALF),
        rgba=list(BOARD_RGBA),
        density=600,
        friction=(1.5, 0.01, 0.003),
    )
    make_static(board)
    body = board.get_obj()
    for geom in body.iter("geom"):  # rolling friction (condim 6): a carrot set down on
        geom.set("condim", "6")  # its side stays where it lies instead of rolling off
    for name, (x, y) in BOARD_SPOTS.items():
        ET.SubElement(
            body,
            "site",
            name=name,
            pos=f"{x} {y} {BOARD_HALF[2]}",
            size="0.004",
            rgba="0 0 0 0",
            group="4",
        )
    return board
