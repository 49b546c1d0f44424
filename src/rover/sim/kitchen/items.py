"""The graspable item of a pick-and-place kitchen task: one free body, many instances.

A kitchen model is built once per process and must fit every seed's saved states, yet
each episode draws which instance of the task's category it handles (a tomato, a
potato, a carrot ...). So the item is one free robosuite body that carries the geoms of
every instance of its category (each built by `rover.sim.kitchen.objects.build_object`
from robosuite's objects and merged into the first one's body); a scene switches one
instance's geoms on and the others off (no collisions, hidden render group) and gives
the body that instance's mass and inertia. The task spec names that one body, so facts,
events and the value function see "the vegetable" whatever instance a seed drew.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rover.sim.kitchen.forward_items import item_instances as instances
from rover.sim.kitchen.objects import Instance

PREFIX = "item_"
HIDDEN_GROUP = 3  # render group of switched-off geoms (the renderer shows groups 0-2 only)
DENSITY = 300.0  # kg/m^3, as the décor objects


def host_body(category: str, prefix: str = PREFIX) -> str:
    """MuJoCo name of the item body of a category (the first instance's robosuite body).

    Pure naming (no robosuite import), so task specs can name it. A scene with several
    items (the composite tasks) gives each its own `prefix`."""
    first = instances(category)[0]
    suffix = "root" if first.shape in ("mug", "pan") else "main"
    return f"{prefix}{first.key}_{suffix}"


def geom_prefix(inst: Instance, prefix: str = PREFIX) -> str:
    """Prefix of every MuJoCo geom name of one instance inside the merged body."""
    return f"{prefix}{inst.key}_"


def mass_inertia(inst: Instance) -> tuple[float, np.ndarray]:
    """Mass (kg) and principal inertia (kg m^2) of an instance as a solid of `DENSITY`.

    Shapes are approximated by their robosuite primitive (a mug by its ring, a pan by a
    flat cylinder); plenty for a gripper carrying it.
    """
    s = inst.size
    if inst.shape == "ball":
        r = s[0]
        m = DENSITY * 4.0 / 3.0 * np.pi * r**3
        return m, np.full(3, 0.4 * m * r * r)
    if inst.shape == "box":
        a, b, c = (2.0 * v for v in s)
        m = DENSITY * a * b * c
        return m, m / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if inst.shape == "mug":
        outer, inner, half = s
        m = DENSITY * np.pi * (outer**2 - inner**2) * 2.0 * half
        rr = outer**2 + inner**2
        side = m / 12.0 * (3.0 * rr + (2.0 * half) ** 2)
        return m, np.array([side, side, 0.5 * m * rr])
    if inst.shape == "pan":
        r, _, half = s
        m = DENSITY * np.pi * r * r * 2.0 * half
        side = m / 12.0 * (3.0 * r * r + (2.0 * half) ** 2)
        return m, np.array([side, side, 0.5 * m * r * r])
    # cylinder (radius, half height) and capsule (radius, half length of the cylinder)
    r, half = s[0], s[1] + (s[0] if inst.shape == "capsule" else 0.0)
    m = DENSITY * np.pi * r * r * 2.0 * half
    side = m / 12.0 * (3.0 * r * r + (2.0 * half) ** 2)
    return m, np.array([side, side, 0.5 * m * r * r])


def build_item(category: str, prefix: str = PREFIX):
    """The merged robosuite object of a category (free joint; first instance's body)."""
    from rover.sim.kitchen.objects import build_object

    members = instances(category)
    host = build_object(members[0], prefix=prefix)
    body = host.get_obj()
    for inst in members[1:]:
        other = build_object(inst, prefix=prefix)
        for geom in other.get_obj().findall("geom"):
            body.append(geom)
        for child in other.asset:
            host.asset.append(child)
    return host


@dataclass
class ItemGeoms:
    """Per instance: its geom ids and their collision bits and render group as built."""

    ids: dict[str, list[int]]
    contype: dict[int, int]
    conaffinity: dict[int, int]
    group: dict[int, int]

    @classmethod
    def of(cls, model, category: str, prefix: str = PREFIX) -> ItemGeoms:
        names = [model.geom(g).name for g in range(model.ngeom)]
        ids = {
            inst.name: [g for g, n in enumerate(names) if n.startswith(geom_prefix(inst, prefix))]
            for inst in instances(category)
        }
        every = [g for gs in ids.values() for g in gs]
        return cls(
            ids,
            {g: int(model.geom_contype[g]) for g in every},
            {g: int(model.geom_conaffinity[g]) for g in every},
            {g: int(model.geom_group[g]) for g in every},
        )

    def show(self, model, name: str, rgb) -> None:
        """Switch instance `name` on (collides, rendered, coloured `rgb`), others off."""
        for inst, gs in self.ids.items():
            for g in gs:
                on = inst == name
                model.geom_contype[g] = self.contype[g] if on else 0
                model.geom_conaffinity[g] = self.conaffinity[g] if on else 0
                model.geom_group[g] = self.group[g] if on else HIDDEN_GROUP
                if on:
                    model.geom_rgba[g][:3] = rgb
