"""Where a pick-and-place item is: the goal and start regions of the kitchen fixtures.

A region is a box in a fixture's own frame (origin on the counter top at the fixture's
base, front facing -x) plus the relation the facts report for an item resting there:
``inside`` the sink basin, the microwave's cavity and the cabinet's lower compartment,
``on`` the stove's cooktop, ``on`` the coffee machine (its drip tray under the spout:
the mug stands on the machine, as "on the stove"), and ``on`` the counter for any free
stretch of counter top (not under a fixture). `OPENINGS` lists the regions reached
through a fixture's front opening, which the forward grasp
(`rover.sim.kitchen.forward_grasp`) serves. An item is in a region when its centre lies
within the box's footprint and its lowest point lies in the box's height band; the
bands reach a few centimetres above the surface, so an item let go just above it (the
scripted expert releases 1-3 cm up) is already in the region while it settles, and one
falling from higher is not (a drop).

Pure data and geometry (no robosuite import): the env and the tests share it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rover.sim.kitchen.fixtures import COUNTER_SIZE, COUNTER_TOP

SETTLE = 0.05  # m above a surface that an item's lowest point may be and still rest there


@dataclass(frozen=True)
class Region:
    """A box in one fixture's frame where items rest.

    Attributes:
        name: what the facts call it ("sink"), also the instruction's wording.
        relation: ``"inside"`` or ``"on"`` (the fact field it is reported in).
        fixture: the fixture it belongs to (None: the counter itself).
        centre, half: box centre and half extents in x, y (fixture frame).
        floor: height of the surface items rest on (fixture frame).
        top: the highest an item's lowest point may be (default: floor + SETTLE).
        start: (x, y) half ranges of where a task's item may start in it, around `centre`.
        site: the fixture site goal points are taken from (fixture prefix added).
    """

    name: str
    relation: str
    fixture: str | None
    centre: tuple[float, float]
    half: tuple[float, float]
    floor: float
    top: float | None = None
    start: tuple[float, float] = (0.02, 0.02)
    site: str = ""

    @property
    def ceiling(self) -> float:
        return self.floor + SETTLE if self.top is None else self.top


REGIONS: dict[str, Region] = {
    r.name: r
    for r in (
        # basin walls (inner faces) at x = +-0.12, y = +-0.17; floor top 1 cm up, rim at
        # 10 cm. Items start in the front half: the spout hangs over the back half
        Region(
            "sink",
            "inside",
            "Sink",
            (0.0, 0.0),
            (0.12, 0.17),
            0.01,
            top=0.10,
            start=(0.015, 0.07),
            site="basin",
        ),
        Region(
            "stove",
            "on",
            "Stove",
            (0.0, 0.0),
            (0.15, 0.2),
            0.04,
            start=(0.012, 0.012),
            site="burner",
        ),
        # the microwave's cavity (inside: walls at x -0.12..0.11, y -0.19..0.08, floor top
        # 1 cm up, roof at 19 cm); items start in its front half, within the hand's reach
        Region(
            "microwave",
            "inside",
            "Microwave",
            (0.0, -0.055),
            (0.11, 0.135),
            0.01,
            start=(0.01, 0.02),
            site="interior",
        ),
        # the coffee machine's drip tray under the spout (top 2 cm up): a mug stands "on"
        # the coffee machine when it rests there, centred within 5 cm of the spout
        Region(
            "coffee machine",
            "on",
            "Coffee",
            (-0.04, 0.0),
            (0.05, 0.06),
            0.02,
            start=(0.006, 0.01),
            site="slot",
        ),
        # the cabinet's lower compartment (inside: walls at x -0.1..0.09, y -0.13..0.13,
        # floor top 1 cm up, shelf at 16.1 cm); items start in its front half
        Region(
            "cabinet",
            "inside",
            "Cabinet",
            (0.0, 0.0),
            (0.09, 0.12),
            0.01,
            start=(0.01, 0.02),
            site="inside",
        ),
        Region("counter", "on", None, (0.0, 0.0), (COUNTER_SIZE[0] / 2, COUNTER_SIZE[1] / 2), 0.0),
    )
}
START_IN = {
    "sink": (-0.06, 0.0),
    "stove": (0.005, -0.1),
    "microwave": (-0.03, -0.055),
    "coffee machine": (-0.04, 0.0),
    "cabinet": (-0.02, 0.0),
}  # start centre (fixture frame)
# regions entered through a fixture's front opening (the coffee machine's: under its
# head): the forward grasp (`rover.sim.kitchen.forward_grasp`) reaches them
OPENINGS = ("microwave", "coffee machine", "cabinet")
# fixture footprints on the counter (half x, half y, fixture frame): an item there is
# not on the counter (it is on the fixture's deck, or in one of its regions)
FOOTPRINT = {
    "Drawer": (0.1, 0.125),
    "Cabinet": (0.11, 0.14),
    "Microwave": (0.13, 0.2),
    "Coffee": (0.12, 0.09),
    "Stove": (0.15, 0.2),
    "Sink": (0.19, 0.18),
}
# where a counter spot (start or goal) is drawn beside the fixture in use: which side
# along the counter (+1: +y), the gap from the fixture's edge and the x range
COUNTER_SIDE = {
    "Sink": 1.0,
    "Stove": -1.0,
    "Microwave": 1.0,
    "Coffee": 1.0,
    "Cabinet": 1.0,
}  # microwave: the panel side. The level hand's reach: on the -y side the ready pose's
# arm family runs joint 2 into its limit at counter height (CoffeeSetupMug 17/20 there)
COUNTER_GAP = (0.09, 0.15)
COUNTER_X = (-0.14, -0.05)


def to_local(point: np.ndarray, origin: np.ndarray, yaw: float) -> np.ndarray:
    """A world point in a fixture's frame (origin on the counter top, yaw about z)."""
    c, s = np.cos(yaw), np.sin(yaw)
    d = np.asarray(point, dtype=np.float64) - origin
    return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], d[2]])


def to_world(local: np.ndarray, origin: np.ndarray, yaw: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    x, y, z = local
    return origin + np.array([c * x - s * y, s * x + c * y, z])


def in_box(region: Region, local_centre: np.ndarray, local_bottom: float) -> bool:
    """Whether an item (centre and lowest point in the region's frame) rests in it."""
    dx = abs(local_centre[0] - region.centre[0])
    dy = abs(local_centre[1] - region.centre[1])
    return bool(
        dx <= region.half[0]
        and dy <= region.half[1]
        and region.floor - 0.01 <= local_bottom <= region.ceiling
    )


def locate(
    centre: np.ndarray, bottom: float, poses: dict[str, tuple[np.ndarray, float]]
) -> tuple[str, str] | None:
    """(relation, region name) the item rests in, or None (held up, falling, on a deck).

    Args:
        centre: the item's centre (world).
        bottom: its lowest point (world z).
        poses: fixture name -> (origin, yaw) of every fixture standing on the counter.
    """
    for region in REGIONS.values():
        if region.fixture is None or region.fixture not in poses:
            continue
        origin, yaw = poses[region.fixture]
        local = to_local(centre, origin, yaw)
        if in_box(region, local, bottom - origin[2]):
            return region.relation, region.name
    for name, (origin, yaw) in poses.items():
        local = to_local(centre, origin, yaw)
        hx, hy = FOOTPRINT[name]
        if abs(local[0]) <= hx and abs(local[1]) <= hy:
            return None
    counter = REGIONS["counter"]
    world = np.array([centre[0], centre[1], 0.0])
    if in_box(counter, world, bottom - COUNTER_TOP):
        return counter.relation, counter.name
    return None
