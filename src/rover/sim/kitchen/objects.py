"""Object instances per category, told apart by shape, size and colour.

The catalogue is plain data (`CATALOGUE`): every instance has a category, a name a
description can use ("red mug") and a procedural shape sized for the Panda gripper.
`build_object` turns one into a robosuite object: its own `HollowCylinderObject` (mugs),
`PotWithHandlesObject` (pans) and primitive `BoxObject` / `CylinderObject` /
`BallObject` / `CapsuleObject` (sponges, food, vegetables, pantry items).
Objects on the counter as décor are static (their free joint is removed): a scene
stores the unused ones below the floor, where a welded body touches nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Instance:
    """One object instance: category, name, robosuite shape and its size (m), RGBA."""

    category: str
    name: str
    shape: str  # "mug", "pan", "box", "cylinder", "ball", "capsule"
    size: tuple[float, ...]
    rgba: tuple[float, float, float, float]

    @property
    def key(self) -> str:
        """MuJoCo-safe object name ("red mug" -> "red_mug")."""
        return self.name.replace(" ", "_")


CATALOGUE: tuple[Instance, ...] = (
    Instance("mug", "red mug", "mug", (0.040, 0.032, 0.045), (0.8, 0.15, 0.12, 1)),
    Instance("mug", "white mug", "mug", (0.037, 0.030, 0.040), (0.92, 0.92, 0.9, 1)),
    Instance("mug", "blue mug", "mug", (0.042, 0.034, 0.035), (0.15, 0.3, 0.75, 1)),
    Instance("pan", "steel pan", "pan", (0.075, 0.075, 0.025), (0.6, 0.6, 0.62, 1)),
    Instance("pan", "black pan", "pan", (0.065, 0.065, 0.03), (0.12, 0.12, 0.13, 1)),
    Instance("sponge", "yellow sponge", "box", (0.04, 0.025, 0.015), (0.95, 0.85, 0.2, 1)),
    Instance("sponge", "green sponge", "box", (0.035, 0.025, 0.018), (0.25, 0.65, 0.3, 1)),
    Instance("food", "frozen steak", "box", (0.05, 0.035, 0.015), (0.6, 0.22, 0.2, 1)),
    Instance("food", "frozen fish", "box", (0.06, 0.025, 0.015), (0.65, 0.72, 0.8, 1)),
    Instance("food", "frozen dumplings", "cylinder", (0.035, 0.02), (0.92, 0.88, 0.75, 1)),
    Instance("vegetable", "tomato", "ball", (0.03,), (0.85, 0.12, 0.1, 1)),
    Instance("vegetable", "potato", "ball", (0.032,), (0.62, 0.48, 0.3, 1)),
    Instance("vegetable", "carrot", "capsule", (0.014, 0.045), (0.95, 0.5, 0.1, 1)),
    Instance("vegetable", "cucumber", "cylinder", (0.02, 0.06), (0.2, 0.5, 0.2, 1)),
    Instance("vegetable", "eggplant", "cylinder", (0.026, 0.05), (0.35, 0.15, 0.4, 1)),
    Instance("pantry", "soup can", "cylinder", (0.033, 0.05), (0.75, 0.1, 0.12, 1)),
    Instance("pantry", "cereal box", "box", (0.025, 0.06, 0.08), (0.9, 0.75, 0.2, 1)),
    Instance("pantry", "spice jar", "cylinder", (0.02, 0.045), (0.5, 0.3, 0.15, 1)),
)
CATEGORIES = sorted({i.category for i in CATALOGUE})

# décor spots on the counter (counter frame x, y): front corners, clear of the reach zone
DECOR_SPOTS = ((-0.28, -0.45), (-0.28, 0.45), (-0.18, -0.55), (-0.18, 0.55))
DECOR_COUNT = 3
COLOUR_JITTER = 0.08  # per-channel RGB jitter of a décor instance's colour


def instances(category: str) -> list[Instance]:
    """Every instance of one category, in catalogue order."""
    found = [i for i in CATALOGUE if i.category == category]
    if not found:
        raise KeyError(f"no object category {category!r}; categories: {', '.join(CATEGORIES)}")
    return found


def draw_decor(rng: np.random.Generator, clear: tuple[float, float] | None = None) -> list[dict]:
    """`DECOR_COUNT` instances of different categories on distinct spots, colours jittered;
    none on a spot whose y lies in the band `clear` (the arm's path around a fixture),
    fewer when fewer spots are left."""
    free = [xy for xy in DECOR_SPOTS if clear is None or not clear[0] <= xy[1] <= clear[1]]
    count = min(DECOR_COUNT, len(free))
    cats = rng.permutation(len(CATEGORIES))[:count]
    spots = rng.permutation(len(free))[:count]
    out = []
    for c, s in zip(cats, spots, strict=True):
        options = instances(CATEGORIES[int(c)])
        inst = options[int(rng.integers(len(options)))]
        rgb = np.clip(np.asarray(inst.rgba[:3]) + rng.uniform(-1, 1, 3) * COLOUR_JITTER, 0, 1)
        x, y = free[int(s)]
        out.append(
            {
                "name": inst.name,
                "category": inst.category,
                "x": x,
                "y": y,
                "yaw": round(float(rng.uniform(-np.pi, np.pi)), 4),
                "rgb": [round(float(v), 3) for v in rgb],
            }
        )
    return out


def half_height(inst: Instance) -> float:
    """Half the instance's height as it stands (its centre sits this far above the top)."""
    if inst.shape == "mug":
        return inst.size[2]
    if inst.shape == "pan":
        return inst.size[2]
    if inst.shape == "box":
        return inst.size[2]
    if inst.shape == "ball":
        return inst.size[0]
    if inst.shape == "capsule":
        return inst.size[0] + inst.size[1]
    return inst.size[1]  # cylinder: (radius, half height)


def build_object(inst: Instance, prefix: str = "decor_"):
    """The robosuite object of one instance (free joint; see `make_static`)."""
    from robosuite.models.objects import (
        BallObject,
        BoxObject,
        CapsuleObject,
        CylinderObject,
        HollowCylinderObject,
        PotWithHandlesObject,
    )

    name = prefix + inst.key
    rgba = list(inst.rgba)
    if inst.shape == "mug":
        outer, inner, half = inst.size
        return HollowCylinderObject(
            name, outer_radius=outer, inner_radius=inner, height=half, rgba=rgba, density=300
        )
    if inst.shape == "pan":
        return PotWithHandlesObject(
            name, body_half_size=inst.size, rgba_body=rgba, use_texture=False, density=300
        )
    kinds = {"box": BoxObject, "cylinder": CylinderObject, "ball": BallObject}
    kinds["capsule"] = CapsuleObject
    return kinds[inst.shape](name, size=list(inst.size), rgba=rgba, density=300)


def make_static(obj) -> None:
    """Weld a robosuite object to the world: drop the free joint from its body."""
    body = obj.get_obj()
    for joint in body.findall("joint") + body.findall("freejoint"):
        body.remove(joint)
    obj._joints = []
