"""Seeded draw of a pick-and-place item and where it rests, for `RoverKitchen`.

`draw_item` picks the instance of the task's category, its colour jitter, its start
pose in the task's start region and the counter spot (start or goal on the counter,
beside the fixture in use), all from the env's seeded generator right after the scene,
so one seed gives one item in any process. `item_place` reads which region the item
rests in from MuJoCo (`rover.sim.kitchen.regions`).
"""

from __future__ import annotations

import numpy as np

from rover.sim.kitchen.fixtures import COUNTER_TOP, FIXTURES
from rover.sim.kitchen.forward_items import item_instances as instances
from rover.sim.kitchen.objects import COLOUR_JITTER, half_height
from rover.sim.kitchen.regions import (
    COUNTER_GAP,
    COUNTER_SIDE,
    COUNTER_X,
    REGIONS,
    START_IN,
    locate,
    to_world,
)


def draw_item(rng: np.random.Generator, env) -> dict:
    """Instance, colour, start pose (free-joint qpos) and counter spot of the task's item."""
    options = instances(env.item_category)
    inst = options[int(rng.integers(len(options)))]
    rgb = np.clip(np.asarray(inst.rgba[:3]) + rng.uniform(-1, 1, 3) * COLOUR_JITTER, 0, 1)
    place = env.scene.layout[env.fixture_name]
    origin = np.array([place.x, place.y, COUNTER_TOP])
    side = COUNTER_SIDE[env.fixture_name]
    gap = float(rng.uniform(*COUNTER_GAP))
    counter = (
        float(rng.uniform(*COUNTER_X)),
        place.y + side * (FIXTURES[env.fixture_name].half_width + gap),
    )
    yaw = float(rng.uniform(-np.pi, np.pi))
    jitter = rng.uniform(-1, 1, 2)
    region = REGIONS[env.item_start]
    if region.fixture is None:
        xy = np.array(counter)
        z = COUNTER_TOP + half_height(inst)
    else:
        cx, cy = START_IN[region.name]
        local = np.array([cx + jitter[0] * region.start[0], cy + jitter[1] * region.start[1], 0.0])
        w = to_world(local, origin, place.yaw)
        xy = w[:2]
        z = COUNTER_TOP + region.floor + half_height(inst)
    qpos = [float(xy[0]), float(xy[1]), z, float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))]
    out = {
        "name": inst.name,
        "category": inst.category,
        "rgb": [round(float(v), 3) for v in rgb],
        "start": env.item_start,
        "goal": env.item_goal,
        "qpos": [round(v, 5) for v in qpos],
        "counter": [round(v, 4) for v in counter],
    }
    if env.kind == "door":  # the fixture's door stands open for the item to pass
        out["door"] = round(float(env.start_q), 4)
    return out


def item_bottom(env) -> float:
    """Lowest world z of the item's switched-on collision geoms, exact per primitive
    (a box corner, a ball's or capsule's cap, a cylinder's rim)."""
    import mujoco

    m, d = env.sim.model._model, env.sim.data._data
    low = np.inf
    for g in env.item_geoms.ids[env.scene.item["name"]]:
        if not m.geom_contype[g]:
            continue
        rot, size, kind = d.geom_xmat[g].reshape(3, 3), m.geom_size[g], m.geom_type[g]
        up = abs(rot[2])  # |z component| of each geom axis
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
            reach = size[0]
        elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
            reach = up[2] * size[1] + size[0]
        elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
            reach = up[2] * size[1] + size[0] * np.sqrt(max(0.0, 1.0 - up[2] ** 2))
        else:  # box (and anything else by its box)
            reach = float(up @ size[:3])
        low = min(low, float(d.geom_xpos[g][2] - reach))
    return low if np.isfinite(low) else float(d.xpos[env.item_body_id][2])


def item_place(env) -> tuple[str, str] | None:
    """(relation, region) the item rests in now, or None."""
    centre = env.sim.data._data.xpos[env.item_body_id]
    return locate(centre, item_bottom(env), env.fixture_poses())
