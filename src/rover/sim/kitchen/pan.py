"""A frying pan with one short handle, for PreSoakPan (pan into the sink, sponge into it).

The catalogue's pans are robosuite `PotWithHandlesObject`s with two 9 cm handles: 33 cm
end to end against the sink basin's 34 cm, so one fits only lowered within 5 mm of the
basin's centre line. This pan is built from robosuite's `CompositeObject` instead: a
round base, a ring of wall segments and one flat handle at rim height along the pan's
local +x, 15-17 cm of pan plus 9 cm of handle (24-26 cm), which lies in the basin with
room to spare when the handle runs along the sink's length.

The pan is grasped from above by its handle (`HANDLE_GRIP` out from the rim, fingers
closing across the handle's width) and carried hanging from it. Its mass is a thin
shell's (`PAN_MASS`), not a solid disc's, so the grip holds it level.

The sponge goes "in the pan": `PAN_REGION` is the pan's floor in the pan's own frame,
so the region moves with the pan wherever it stands (on the counter or in the sink).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rover.sim.kitchen.objects import Instance
from rover.sim.kitchen.regions import SETTLE

BASE_HALF = 0.004  # m: half thickness of the pan's base
WALL = 0.006  # m: wall thickness
SEGMENTS = 16  # wall segments around the rim
HANDLE_HALF = (0.045, 0.011, 0.007)  # m: handle half length (radial), width, thickness
HANDLE_GRIP = 0.035  # m out from the rim the fingers close on the handle
PAN_MASS = 0.12  # kg: a thin pan, light enough to hang level from a two-finger grip
HANDLE_SITE = "handle"  # site names on the pan body (the host instance's prefix added)
INSIDE_SITE = "inside"


def handle_length(inst: Instance) -> float:
    """End-to-end length of the pan with its handle (m)."""
    return 2 * inst.size[0] + 2 * HANDLE_HALF[0]


def site_positions(inst: Instance) -> dict[str, tuple[float, float, float]]:
    """Body-frame positions of the handle grip point and the pan's floor centre."""
    r, _, h = inst.size
    return {
        HANDLE_SITE: (r + HANDLE_GRIP, 0.0, h - HANDLE_HALF[2]),
        INSIDE_SITE: (0.0, 0.0, -h + 2 * BASE_HALF),
    }


def pan_mass_inertia(inst: Instance) -> tuple[float, np.ndarray]:
    """Mass and principal inertia of the pan as a thin disc of `PAN_MASS` (kg, kg m^2)."""
    r, _, h = inst.size
    side = PAN_MASS / 12.0 * (3.0 * r * r + (2.0 * h) ** 2)
    return PAN_MASS, np.array([side, side, 0.5 * PAN_MASS * r * r])


@dataclass(frozen=True)
class PanRegion:
    """Where an item rests in a pan: its centre within `margin` of the wall's inside,
    its lowest point between 1 cm below the pan's floor and `SETTLE` above it."""

    name: str = "pan"
    margin: float = 0.015

    def holds(self, inst: Instance, local_centre, local_bottom: float) -> bool:
        r, _, h = inst.size
        floor = -h + 2 * BASE_HALF
        radial = float(np.hypot(local_centre[0], local_centre[1]))
        return bool(
            radial <= r - WALL - self.margin and floor - 0.01 <= local_bottom <= floor + SETTLE
        )


PAN_REGION = PanRegion()


def _geoms(inst: Instance) -> dict[str, list]:
    """CompositeObject geometry: base, wall ring, handle (centre-relative)."""
    r, _, h = inst.size
    rgba = list(inst.rgba)
    keys = ("types", "sizes", "locations", "quats", "names", "obj_types")
    out: dict[str, list] = {k: [] for k in keys}

    def add(kind: str, size, pos, yaw: float, name: str, use: str = "all") -> None:
        out["types"].append(kind)
        out["sizes"].append(list(size))
        out["locations"].append(list(pos))
        out["quats"].append([float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))])
        out["names"].append(name)
        out["obj_types"].append(use)

    # the round base is only seen: MuJoCo's cylinder-box contact lets a wide flat
    # cylinder sink into the counter, so a square inscribed in it carries the pan
    add("cylinder", (r, BASE_HALF), (0.0, 0.0, -h + BASE_HALF), 0.0, "base", "visual")
    side = (r - WALL) / np.sqrt(2.0)
    add("box", (side, side, BASE_HALF), (0.0, 0.0, -h + BASE_HALF), 0.0, "floor", "collision")
    wall_half_z = h - BASE_HALF
    seg_half = (r - WALL / 2) * np.tan(np.pi / SEGMENTS) + 0.001  # slight overlap
    for k in range(SEGMENTS):
        a = 2 * np.pi * k / SEGMENTS
        c = r - WALL / 2
        add(
            "box",
            (WALL / 2, seg_half, wall_half_z),
            (c * np.cos(a), c * np.sin(a), BASE_HALF),
            a,
            f"wall{k}",
        )
    hx, hy, hz = HANDLE_HALF
    add("box", (hx, hy, hz), (r - WALL / 2 + hx, 0.0, h - hz), 0.0, "handle")
    out["rgbas"] = [rgba] * len(out["names"])
    return out


def build_pan(inst: Instance, prefix: str):
    """One pan instance as a robosuite `CompositeObject` (free joint), named as
    `rover.sim.kitchen.objects.build_object` names its objects (prefix + key)."""
    from robosuite.models.objects import CompositeObject

    g = _geoms(inst)
    r, _, h = inst.size
    reach = r + 2 * HANDLE_HALF[0]
    return CompositeObject(
        prefix + inst.key,
        total_size=[reach, reach, h],
        geom_types=g["types"],
        geom_sizes=g["sizes"],
        geom_locations=g["locations"],
        geom_quats=g["quats"],
        geom_names=g["names"],
        geom_rgbas=g["rgbas"],
        geom_frictions=[(1.2, 0.005, 0.0001)] * len(g["names"]),
        density=300,
        locations_relative_to_center=True,
        obj_types=g["obj_types"],
    )


def build_pan_item(prefix: str):
    """Every pan instance merged into one free body (as `rover.sim.kitchen.items`
    merges a category), plus the handle and floor sites the scene moves per instance."""
    import xml.etree.ElementTree as ET

    from rover.sim.kitchen.objects import instances

    members = instances("pan")
    host = build_pan(members[0], prefix)
    body = host.get_obj()
    for inst in members[1:]:
        for geom in build_pan(inst, prefix).get_obj().findall("geom"):
            body.append(geom)
    for name, pos in site_positions(members[0]).items():
        ET.SubElement(
            body,
            "site",
            name=f"{host.naming_prefix}{name}",
            pos=" ".join(f"{v:.4f}" for v in pos),
            size="0.004",
            rgba="0 0 0 0",
            group="4",
        )
    return host


def site_name(prefix: str, which: str) -> str:
    """MuJoCo name of a pan site (pure naming, for task specs)."""
    from rover.sim.kitchen.items import host_body

    root = host_body("pan", prefix)
    return root[: -len("root")] + which
