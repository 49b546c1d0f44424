"""`RoverKitchenComposite`: the kitchen with several free items and utensils at once.

The composite tasks of Table 4 move more than one object (two vegetables onto a
cutting board, a pan into the sink and a sponge into the pan) and may then work a
fixture part (the sink's faucet handle). `RoverKitchen` carries one pick-and-place item;
this subclass adds any number of named items, each its own free body holding every
instance of its category (`rover.sim.kitchen.items`, one geom prefix per item, so two
vegetables of one scene are two bodies and two different instances), and the cutting
board (`rover.sim.kitchen.utensils`). Per item the facts ask `object_place` (the region
it rests in: the board, a fixture region or the counter) and the predicates
`object_in_goal`; the fixture part keeps `FixtureEnv`'s joint interface when the task
works it (``articulated``), so the articulation facts and experts apply unchanged.

Everything drawn (instances, colours, start poses, the board's pose) comes from the
env's seeded generator right after the base scene, and is recorded in ``episode.json``
under ``extra.scene.objects`` and ``extra.scene.board``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from rover.sim.kitchen.env import RoverKitchen, _yaw_quat
from rover.sim.kitchen.fixtures import COUNTER_TOP
from rover.sim.kitchen.items import ItemGeoms, build_item, mass_inertia
from rover.sim.kitchen.objects import CATALOGUE, COLOUR_JITTER, half_height, instances
from rover.sim.kitchen.placement import item_bottom
from rover.sim.kitchen.regions import locate, to_local
from rover.sim.kitchen.scene import Scene
from rover.sim.kitchen.utensils import (
    BOARD_BODY,
    BOARD_REGION,
    BOARD_X,
    BOARD_Y,
    BOARD_YAW,
    START_SPOTS,
    ItemRole,
    build_board,
)


@dataclass
class CompositeScene(Scene):
    """A kitchen scene plus the composite task's items and the board (JSON-able)."""

    objects: list[dict] = field(default_factory=list)
    board: dict | None = None


class RoverKitchenComposite(RoverKitchen):
    """The kitchen with named free items (`items`) and optionally the cutting board.

    Args:
        robots: robosuite robot spec.
        fixture, part: the fixture standing in reach and its part (see `RoverKitchen`).
        items: ``[name, category, start, goal]`` per item (`ItemRole`).
        board: whether the cutting board stands on the counter.
        articulated: whether the task works the fixture part (its joint facts and
            success); otherwise the fixture is only scenery.
        **kwargs: as `RoverKitchen` (``facts_as``, ``start_q``, ``target``, ...).
    """

    def __init__(
        self,
        robots,
        fixture: str = "Cabinet",
        part: str = "door",
        items: list | tuple = (),
        board: bool = False,
        articulated: bool = False,
        **kwargs,
    ) -> None:
        self.roles = [ItemRole(*r) for r in items]
        self.has_board = board
        self.articulated = articulated
        self.role_geoms: dict[str, ItemGeoms] = {}
        super().__init__(robots, fixture=fixture, part=part, **kwargs)

    # the fixture's part is the task's articulation only when the task works it
    @property
    def part(self) -> str:
        return self._part if self.articulated else ""

    @part.setter
    def part(self, value: str) -> None:
        self._part = value

    # ---------------------------------------------------------------- model
    def _load_model(self) -> None:
        super()._load_model()
        self.free_items = {r.name: build_item(r.category, r.prefix) for r in self.roles}
        extra = list(self.free_items.values())
        if self.has_board:
            self.board = build_board()
            extra.append(self.board)
        self.model.merge_objects(extra)
        self.model.mujoco_objects.extend(extra)

    def _setup_references(self) -> None:
        super()._setup_references()
        m = self.sim.model
        self.role_body_ids = {n: m.body_name2id(o.root_body) for n, o in self.free_items.items()}
        self.role_qpos = {n: m.get_joint_qpos_addr(o.joints[0]) for n, o in self.free_items.items()}
        self.role_dof = {
            n: int(m._model.jnt_dofadr[m.joint_name2id(o.joints[0])])
            for n, o in self.free_items.items()
        }
        if not self.role_geoms:  # once: later calls see a scene's switched geoms
            self.role_geoms = {
                r.name: ItemGeoms.of(m._model, r.category, r.prefix) for r in self.roles
            }
        self.board_body_id = m.body_name2id(BOARD_BODY) if self.has_board else None

    # ---------------------------------------------------------------- reset
    def _reset_internal(self) -> None:
        super()._reset_internal()
        base = {k: getattr(self.scene, k) for k in Scene.__dataclass_fields__}
        objects, board = self._draw_composite()
        self.scene = CompositeScene(**base, objects=objects, board=board)
        self.apply_scene(self.scene)
        d = self.sim.data
        for obj in objects:
            a, b = self.role_qpos[obj["role"]]
            d.qpos[a:b] = obj["qpos"]
            dof = self.role_dof[obj["role"]]
            d.qvel[dof : dof + 6] = 0.0
        self.sim.forward()

    def _draw_composite(self) -> tuple[list[dict], dict | None]:
        """Instances (all different), colours and start poses of the items; the board."""
        rng = self.rng
        board = None
        if self.has_board:
            board = {
                "x": round(float(rng.uniform(*BOARD_X)), 4),
                "y": round(float(rng.uniform(*BOARD_Y)), 4),
                "yaw": round(float(rng.uniform(*BOARD_YAW)), 4),
            }
        used: set[str] = set()
        objects = []
        for role in self.roles:
            options = [i for i in instances(role.category) if i.name not in used]
            inst = options[int(rng.integers(len(options)))]
            used.add(inst.name)
            rgb = np.clip(np.asarray(inst.rgba[:3]) + rng.uniform(-1, 1, 3) * COLOUR_JITTER, 0, 1)
            (x0, x1), (y0, y1) = START_SPOTS[role.start]
            x, y = float(rng.uniform(x0, x1)), float(rng.uniform(y0, y1))
            yaw = float(rng.uniform(-np.pi, np.pi))
            z = COUNTER_TOP + half_height(inst)
            qpos = [x, y, z, float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))]
            objects.append(
                {
                    "role": role.name,
                    "name": inst.name,
                    "category": inst.category,
                    "rgb": [round(float(v), 3) for v in rgb],
                    "start": role.start,
                    "goal": role.goal,
                    "qpos": [round(v, 5) for v in qpos],
                }
            )
        return objects, board

    def apply_scene(self, scene: Scene) -> None:
        super().apply_scene(scene)
        if not isinstance(scene, CompositeScene):
            return  # the base scene, before the composite parts are drawn
        m = self.sim.model._model
        for obj in scene.objects:
            name = obj["role"]
            self.role_geoms[name].show(m, obj["name"], obj["rgb"])
            inst = next(i for i in CATALOGUE if i.name == obj["name"])
            bid = self.role_body_ids[name]
            m.body_mass[bid], m.body_inertia[bid] = mass_inertia(inst)
            m.body_ipos[bid] = 0.0
            m.body_iquat[bid] = [1.0, 0.0, 0.0, 0.0]
        if self.board_body_id is not None and scene.board is not None:
            b = scene.board
            m.body_pos[self.board_body_id] = [b["x"], b["y"], COUNTER_TOP + BOARD_REGION.top]
            m.body_quat[self.board_body_id] = _yaw_quat(b["yaw"])
        self.sim.forward()

    # ------------------------------------------------------------- item facts
    def role(self, name: str) -> ItemRole:
        return next(r for r in self.roles if r.name == name)

    def object_bottom(self, name: str) -> float:
        """Lowest world z of the item's drawn instance (`placement.item_bottom`'s rule)."""
        shown = next(o["name"] for o in self.scene.objects if o["role"] == name)
        view = SimpleNamespace(  # item_bottom reads one item's geoms off an env-like object
            sim=self.sim,
            item_geoms=self.role_geoms[name],
            scene=SimpleNamespace(item={"name": shown}),
            item_body_id=self.role_body_ids[name],
        )
        return item_bottom(view)

    def object_place(self, name: str) -> tuple[str, str] | None:
        """(relation, region) item `name` rests in now: on the board, in or on a fixture
        region, on the counter; None while held up, falling or on a fixture's deck.
        Not an item of this scene (a fixture part): None."""
        if name not in self.role_body_ids or not isinstance(self.scene, CompositeScene):
            return None
        centre = self.sim.data._data.xpos[self.role_body_ids[name]]
        bottom = self.object_bottom(name)
        if self.board_body_id is not None:
            d = self.sim.data._data
            origin = d.xpos[self.board_body_id]
            yaw = float(self.scene.board["yaw"])
            local = to_local(centre, origin, yaw)
            if BOARD_REGION.holds(local, bottom - origin[2]):
                return "on", BOARD_REGION.name
        return locate(centre, bottom, self.fixture_poses())

    def object_in_goal(self, name: str) -> bool:
        found = self.object_place(name)
        return found is not None and found[1] == self.role(name).goal

    def _check_success(self) -> bool:
        if not self.roles:
            return super()._check_success()
        done = all(self.object_in_goal(r.name) for r in self.roles)
        return done and (not self.articulated or bool(self.reached()))
