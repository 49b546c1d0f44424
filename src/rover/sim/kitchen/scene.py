"""The seeded draw of one kitchen scene: layout, textures, lighting, camera, décor.

`draw_scene` turns the episode's random generator into a `Scene`: plain JSON-able
choices that `rover.sim.kitchen.env` applies to the MuJoCo model at reset and that the
generator records in ``episode.json`` (``extra["scene"]``). The scene is a function of
the seed alone, so one seed gives the same kitchen in any process or worker count.

Textures are robosuite's own (``robosuite/models/assets/textures``); each surface's
candidates are compiled into the model as materials once, and a scene only switches
which material a geom shows, so nothing is re-uploaded to the renderer.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from rover.sim.kitchen.fixtures import FIXTURES, SLOTS, Fixture

# robosuite texture files per surface (cube textures for boxes, 2D for planes/walls)
TEXTURES: dict[str, tuple[str, ...]] = {
    "floor": (
        "light-gray-floor-tile",
        "wood-tiles",
        "gray-felt",
        "dark-wood",
        "wood-varnished-panels",
    ),
    "wall": (
        "light-gray-plaster",
        "cream-plaster",
        "white-plaster",
        "yellow-plaster",
        "pink-plaster",
        "white-bricks",
        "gray-plaster",
    ),
    "counter": ("ceramic", "steel-brushed", "gray-woodgrain", "light-wood", "dark-wood", "clay"),
    "wood": ("light-wood", "dark-wood", "red-wood", "blue-wood", "green-wood", "gray-woodgrain"),
}


@dataclass
class Placement:
    """Where one fixture stands: counter-frame origin (m) and yaw (rad); None = stored away."""

    x: float
    y: float
    yaw: float


@dataclass
class Scene:
    """Everything drawn for one episode's kitchen (recorded in ``episode.json``)."""

    layout: dict[str, Placement | None]
    textures: dict[str, str]  # surface -> robosuite texture name
    light_seed: int  # seeds robosuite's LightingModder
    camera_seed: int  # seeds robosuite's CameraModder (small pose jitter)
    decor: list[dict] = field(default_factory=list)  # object instances on the counter
    # pick and place: the item's instance, colour, start pose and counter spot (`placement`)
    item: dict | None = None

    def to_json(self) -> dict:
        out = asdict(self)
        out["layout"] = {
            k: None if v is None else {a: round(b, 4) for a, b in v.items()}
            for k, v in out["layout"].items()
        }
        return out


def draw_layout(
    rng: np.random.Generator,
    used: list[str],
    narrowed: dict[str, Fixture] | None = None,
) -> dict[str, Placement | None]:
    """Fixtures the task uses stand in reach (ranges of `FIXTURES`, or of a task's
    `narrowed` copy of a fixture: `narrow_fixture`), the rest in far slots.

    Two used fixtures share the reach zone side by side: the first keeps its drawn y, the
    second is moved along the counter until their footprints are 5 cm apart.
    """
    layout: dict[str, Placement | None] = {}
    taken: list[tuple[float, float]] = []  # (y, half width) of fixtures in reach
    for name in used:
        fx = (narrowed or {}).get(name, FIXTURES[name])
        y = float(rng.uniform(*fx.y_range))
        for ty, tw in taken:
            gap = tw + fx.half_width + 0.05
            if abs(y - ty) < gap:
                y = ty + gap if y >= ty else ty - gap
        taken.append((y, fx.half_width))
        layout[name] = Placement(
            float(rng.uniform(*fx.x_range)), y, float(rng.uniform(*fx.yaw_range))
        )
    others = [n for n in FIXTURES if n not in used]
    order = rng.permutation(len(others))
    free = [s for s in SLOTS if all(abs(s - ty) > tw + 0.25 for ty, tw in taken)]
    for k, idx in enumerate(order):
        name = others[int(idx)]
        if k < len(free):
            layout[name] = Placement(FIXTURES[name].x, float(free[k]), 0.0)
        else:
            layout[name] = None
    return {n: layout[n] for n in FIXTURES}


def draw_scene(
    rng: np.random.Generator,
    used: list[str],
    decor: list[dict],
    narrowed: dict[str, Fixture] | None = None,
) -> Scene:
    """One kitchen: layout, a texture per surface, light and camera modder seeds."""
    layout = draw_layout(rng, used, narrowed)
    return Scene(layout=layout, decor=decor, **draw_style(rng))


def draw_style(rng: np.random.Generator) -> dict:
    """The purely visual part of a scene: textures, light and camera modder seeds.

    Nothing physical depends on it, so an episode may redraw it (`restyle`) while
    replaying a demonstration recorded in the same layout.
    """
    return {
        "textures": {s: str(opts[int(rng.integers(len(opts)))]) for s, opts in TEXTURES.items()},
        "light_seed": int(rng.integers(2**31)),
        "camera_seed": int(rng.integers(2**31)),
    }


def scene_record(sim) -> dict:
    """``{"scene": ...}`` for ``episode.json`` when `sim` is a kitchen, else ``{}``.

    Call it with the simulator reset to the episode's demonstration seed: the scene is
    the one that seed drew (the one the episode's frames show).
    """
    scene = getattr(sim.env, "scene", None)
    return {"scene": scene.to_json()} if isinstance(scene, Scene) else {}
