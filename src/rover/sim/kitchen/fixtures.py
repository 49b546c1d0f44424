"""What each kitchen fixture is: its MJCF, its size on the counter and where it may stand.

Pure data (no robosuite import), shared by the scene draw and the environment. Every
fixture's front faces -x (the robot). `x`/`y`/`yaw` ranges say where the fixture's origin
may be drawn when a task uses it, chosen so its part (handle, button, knob) lies in the
Panda's comfortable reach; fixtures a task does not use stand in the far `SLOTS` along the
counter, where they are seen but not in the way.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

HERE = Path(__file__).resolve().parent
ASSETS = HERE / "assets"
TABLETOP_FIXTURES = HERE.parent / "fixtures"

COUNTER_SIZE = (0.8, 2.4, 0.05)  # m: the counter box (depth along x, length along y, top)
COUNTER_TOP = 0.8  # m: counter top height
SLOTS = (-1.0, -0.62, 0.62, 1.0)  # m along the counter (y) for the fixtures not in use


@dataclass(frozen=True)
class Fixture:
    """One kitchen fixture type.

    Attributes:
        name: MuJoCo name prefix ("Microwave" -> bodies ``Microwave_door``, ...).
        xml: its MJCF file.
        half_width: half its extent along the counter (y), m.
        x: origin x (counter frame) when standing in a far slot.
        x_range, y_range, yaw_range: where its origin is drawn when a task uses it.
        joints: articulated part -> joint name inside the MJCF.
        wood: geoms (visual copies) that take the cabinet-wood texture of the scene.
    """

    name: str
    xml: Path
    half_width: float
    x: float
    x_range: tuple[float, float]
    y_range: tuple[float, float]
    yaw_range: tuple[float, float] = (-0.1, 0.1)
    joints: dict[str, str] = field(default_factory=dict)
    wood: tuple[str, ...] = ()


FIXTURES: dict[str, Fixture] = {
    f.name: f
    for f in (
        Fixture(
            "Drawer",
            TABLETOP_FIXTURES / "drawer.xml",  # the tabletop drawer unit, reused as is
            0.125,
            0.16,
            (0.14, 0.18),
            (-0.06, 0.06),
            (-0.15, 0.15),
            {"drawer": "slide"},
            ("floor", "top", "left", "right", "back", "front"),
        ),
        Fixture(
            "Cabinet",
            ASSETS / "cabinet.xml",
            0.14,
            0.16,
            (0.14, 0.17),
            (-0.11, -0.05),
            (-0.1, 0.1),
            {"door": "door"},
            ("bottom", "roof", "back", "side_l", "side_r", "shelf", "panel"),
        ),
        Fixture(
            "Microwave",
            ASSETS / "microwave.xml",
            0.2,
            0.16,
            (0.07, 0.12),
            (-0.2, -0.02),
            (-0.2, 0.2),
            {"button": "button", "door": "door", "stop": "stop"},
        ),
        Fixture(
            "Coffee",
            ASSETS / "coffee.xml",
            0.09,
            0.16,
            (0.08, 0.13),
            (-0.1, 0.1),
            (-0.2, 0.2),
            {"button": "button"},
        ),
        Fixture(
            "Stove",
            ASSETS / "stove.xml",
            0.2,
            0.18,
            (0.12, 0.18),
            (0.02, 0.18),
            (-0.2, 0.2),
            {"knob": "knob"},
        ),
        Fixture(
            "Sink",
            ASSETS / "sink.xml",
            0.18,
            0.0,
            (-0.1, -0.06),
            (-0.19, -0.05),
            (-0.15, 0.15),
            {"knob": "knob", "spout": "spout"},
        ),
    )
}


def narrow_fixture(
    name: str,
    x_range: tuple[float, float] | list[float] | None = None,
    y_range: tuple[float, float] | list[float] | None = None,
    yaw_range: tuple[float, float] | list[float] | None = None,
) -> Fixture:
    """`FIXTURES[name]` with a task's own, narrower ranges for its origin's x, y and yaw.

    A task whose expert cannot work every pose the fixture allows draws from a part of
    it (MicrowaveThawing: `rover.sim.kitchen.thawing`). The draw takes as many random
    numbers as before, so the rest of the scene (textures, lights, the other fixtures)
    stays the seed's.
    Raises ValueError for a range not inside the fixture's own.
    """
    fx = FIXTURES[name]
    out = {}
    wanted = (("x_range", x_range), ("y_range", y_range), ("yaw_range", yaw_range))
    for field_name, want in wanted:
        if want is None:
            continue
        own = getattr(fx, field_name)
        lo, hi = (float(v) for v in want)
        if not own[0] <= lo < hi <= own[1]:
            raise ValueError(f"{name} {field_name[:-6]} range {[lo, hi]} is not inside {list(own)}")
        out[field_name] = (lo, hi)
    return replace(fx, **out)
