"""Pick-and-place group: robosuite PickPlace single-object variants and NutAssembly."""

from __future__ import annotations

from rover.sim.tasks._common import pick_place_protocol
from rover.sim.tasks.base import GoalSpec, ObjectSpec, TaskSpec

# robosuite PickPlace: object -> compartment index of the target bin (object_to_id)
BIN_OF = {"milk": 0, "bread": 1, "cereal": 2, "can": 3}
BODY_OF = {"milk": "Milk_main", "bread": "Bread_main", "cereal": "Cereal_main", "can": "Can_main"}


def bin_name(obj: str) -> str:
    """Human name of an object's target compartment: "bin 1" .. "bin 4"."""
    return f"bin {BIN_OF[obj] + 1}"


def pick_place_task(obj: str) -> TaskSpec:
    target = f"in {bin_name(obj)}"
    return TaskSpec(
        name=f"PickPlace{obj.capitalize()}",
        env_name=f"PickPlace{obj.capitalize()}",
        description=f"Pick up the {obj} and place it {target}.",
        objects=[ObjectSpec(name=obj, body=BODY_OF[obj])],
        goals={"bin": GoalSpec(kind="bin", object=obj)},
        bins={obj: BIN_OF[obj]},
        **pick_place_protocol(obj, target, "goal:bin"),
    )


def nut_task(shape: str) -> TaskSpec:
    cap = shape.capitalize()
    nut = f"{shape} nut"
    peg = "peg1" if shape == "square" else "peg2"
    target = f"onto the {shape} peg"
    return TaskSpec(
        name=f"NutAssembly{cap}",
        env_name=f"NutAssembly{cap}",
        description=f"Pick up the {nut} by its handle and put it {target}.",
        objects=[
            ObjectSpec(
                name=nut,
                body=f"{cap}Nut_main",
                centre=f"{cap}Nut_center_site",
                sites={"handle": f"{cap}Nut_handle_site"},
            ),
            ObjectSpec(name="peg", body=peg, graspable=False),
        ],
        goals={"peg": GoalSpec(kind="body", body=peg, offset=(0.0, 0.0, 0.0))},
        **pick_place_protocol(
            nut, target, "goal:peg", f"on_peg:{nut}", point=f"{nut}:handle", expert="nut"
        ),
    )


TASKS = [pick_place_task(o) for o in ("can", "milk", "bread", "cereal")] + [
    nut_task("square"),
    nut_task("round"),
]
