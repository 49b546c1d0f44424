"""Items taken with the forward grasp: instances sized for a hand pointing into an opening.

The object catalogue's items (`rover.sim.kitchen.objects.CATALOGUE`) are sized for the
top-down grasp and appear as décor in every scene; the microwave's and cabinet's items
are held from the side by a horizontal hand whose fingers open 8 cm and whose palm
stands 3.5 cm above the surface, so they are upright, at most 6.2 cm across at any yaw
and 7-9 cm tall. They live in their own table so the décor draw (and every existing
kitchen scene) stays as it was.
"""

from __future__ import annotations

from rover.sim.kitchen.objects import CATALOGUE, Instance

FORWARD_CATALOGUE: tuple[Instance, ...] = (
    # food containers for the microwave: round tubs and a square carton
    Instance("food container", "noodle cup", "cylinder", (0.027, 0.04), (0.95, 0.9, 0.78, 1)),
    Instance("food container", "soup tub", "cylinder", (0.03, 0.035), (0.9, 0.45, 0.15, 1)),
    Instance("food container", "rice carton", "box", (0.021, 0.021, 0.04), (0.45, 0.7, 0.35, 1)),
    # pantry items for the cabinet: a can, a jar and a carton
    Instance("pantry item", "bean can", "cylinder", (0.03, 0.04), (0.7, 0.15, 0.15, 1)),
    Instance("pantry item", "jam jar", "cylinder", (0.024, 0.037), (0.55, 0.1, 0.3, 1)),
    Instance("pantry item", "juice carton", "box", (0.02, 0.024, 0.042), (0.95, 0.65, 0.15, 1)),
    # mugs for the coffee machine (robosuite HollowCylinderObject rings): three sizes
    Instance("mug", "travel mug", "mug", (0.03, 0.025, 0.045), (0.2, 0.25, 0.3, 1)),
    Instance("mug", "green mug", "mug", (0.031, 0.026, 0.038), (0.2, 0.6, 0.35, 1)),
    Instance("mug", "cream cup", "mug", (0.028, 0.023, 0.036), (0.93, 0.88, 0.75, 1)),
)


def item_instances(category: str) -> list[Instance]:
    """Every instance of a pick-and-place category, in table order: the forward-grasp
    table's if it has the category, else the object catalogue's."""
    found = [i for i in FORWARD_CATALOGUE if i.category == category]
    if found:
        return found
    from rover.sim.kitchen.objects import instances

    return instances(category)


def instance_named(name: str) -> Instance:
    """The instance called `name` in either table."""
    return next(i for i in (*FORWARD_CATALOGUE, *CATALOGUE) if i.name == name)
