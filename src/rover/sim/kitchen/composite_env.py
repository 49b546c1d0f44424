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

import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from rover.sim.kitchen.env import RoverKitchen, _yaw_quat
from rover.sim.kitchen.fixtures import COUNTER_TOP, FIXTURES
from rover.sim.kitchen.forward_items import instance_named
from rover.sim.kitchen.forward_items import item_instances as instances  # (forward table first)
from rover.sim.kitchen.items import ItemGeoms, build_item, mass_inertia
from rover.sim.kitchen.objects import COLOUR_JITTER, Instance, half_height
from rover.sim.kitchen.pan import PAN_REGION, build_pan_item, pan_mass_inertia, site_positions
from rover.sim.kitchen.placement import item_bottom
from rover.sim.kitchen.regions import locate, to_local
from rover.sim.kitchen.scene import Scene
from rover.sim.kitchen.utensils import (
    BESIDE_SPOTS,
    BOARD_BODY,
    BOARD_REGION,
    BOARD_X,
    BOARD_Y,
    BOARD_YAW,
    START_SPOTS,
    START_YAW,
    ItemRole,
    build_board,
)


def own_inertial_frame(obj, mass: float, inertia) -> None:
    """Give an item body an explicit inertial frame at its origin, axes unturned.

    A scene sets the body's mass and inertia for its drawn instance in that frame
    (`body_ipos` 0, `body_iquat` identity), but MuJoCo builds a body's collision bounding
    volumes in the inertial frame it compiled. Left to the compiler, the two sponges'
    principal axes came out a quarter turn about y and the pan's sat off centre toward
    its handle: the bounding boxes then stood off the geoms and contacts went missing
    (the fingers closed through the pan's handle, a sponge fell through the pan's floor).
    """
    ET.SubElement(
        obj.get_obj(),
        "inertial",
        pos="0 0 0",
        mass=f"{mass:.6g}",
        diaginertia=" ".join(f"{v:.6g}" for v in inertia),
    )


DECOR_GAP = 0.2  # m: a décor piece's centre stands at least this far beyond an item's reach
# m robosuite's `PotWithHandlesObject` handles stick out beyond its body (handle_length
# 0.09 and radius 0.01, its defaults, which `build_object` keeps)
POT_HANDLE_REACH = 0.1


def decor_overhang(inst: Instance) -> float:
    """How far a décor piece reaches past what `DECOR_GAP` allows for (m).

    The gap was set for the small pieces (at most 6 cm from their centre), so they add
    nothing; a pot's body and two handles reach 17 cm and add all of it.
    """
    return inst.size[0] + POT_HANDLE_REACH if inst.shape == "pan" else 0.0


def clear_decor(decor: list[dict], objects: list[dict]) -> list[dict]:
    """The scene's décor without the pieces standing where the task's items are handled:
    a décor pan's 9 cm handles reached 1 cm from PreSoakPan's pan handle and stopped the
    fingers above it, and in MicrowaveThawing a décor pot's handle 13 cm from the food
    stopped the hand picking it (its centre was 33 cm off). An item's reach is its half
    extent (a pan with its handle); a pot's own reach counts too (`decor_overhang`)."""
    from rover.sim.kitchen.pan import handle_length

    kept = []
    for d in decor:
        near = False
        own = decor_overhang(instance_named(d["name"]))
        for obj in objects:
            inst = instance_named(obj["name"])
            reach = handle_length(inst) / 2 if inst.category == "pan" else max(inst.size[:2])
            gap = float(np.hypot(d["x"] - obj["qpos"][0], d["y"] - obj["qpos"][1]))
            near = near or gap < reach + own + DECOR_GAP
        if not near:
            kept.append(d)
    return kept


@dataclass(frozen=True)
class WorkedPart:
    """One fixture part a composite task works, one entry per subtask that moves a joint.

    A part may be worked more than once (the microwave door opened, later closed): each
    time is its own entry, with its own `key`, start and target on the same joint.

    Attributes:
        key: what the subtask's ``joint:<key>`` point and its ``fixture`` goal's
            ``object`` name it by ("microwave door closed").
        part: the fixture's part (`rover.sim.kitchen.fixtures.Fixture.joints`): "door".
        facts_as: the name the facts and events give the part ("microwave door"); the
            same for every entry on one joint.
        start_q, target, reach: as `FixtureEnv`'s, for this entry's motion.
        with_items: the entry counts as reached only with every item in its goal. A
            door closed again ends where it started: shut, the subtask's end test would
            already hold at the first frame (and progress would value the start as that
            subtask done); shut on the food inside is what the subtask achieves.
    """

    key: str
    part: str
    facts_as: str
    start_q: float = 0.0
    target: float = 0.0
    reach: float = 0.9
    with_items: bool = False


# the FixtureEnv attributes saying which joint is "the" joint and its motion (`working`)
_ACTIVE = ("kind", "_part", "joint", "joint_name", "joint_id", "joint_qpos_addr")
_MOTION = ("start_q", "target", "reach")


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
        scenery_q: start values of the fixture's other joints (part name -> value):
            PreSoakPan's sink spout stands swung aside, out of the arm's way.
        articulated: whether the task works the fixture part (its joint facts and
            success); otherwise the fixture is only scenery.
        parts: several parts of the fixture worked in order (`WorkedPart` fields per
            entry): the door, then the start button. The first entry is the env's joint;
            `working(key)` makes another one it, so the articulation facts, goals and
            experts read that part (`rover.sim.articulation` asks every entry for its
            facts). Implies ``articulated``; `part`, ``facts_as`` and the motion
            arguments are then the first entry's.
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
        scenery_q: dict[str, float] | None = None,
        parts: list[dict] | tuple = (),
        **kwargs,
    ) -> None:
        self.roles = [ItemRole(*r) for r in items]
        self.has_board = board
        self.worked = [WorkedPart(**p) for p in parts]
        if len({w.key for w in self.worked}) != len(self.worked):
            raise ValueError(f"worked parts need distinct keys: {[w.key for w in self.worked]}")
        if self.worked:
            first = self.worked[0]
            part = first.part
            kwargs.update(facts_as=first.facts_as, start_q=first.start_q)
            kwargs.update(target=first.target, reach=first.reach)
        self.articulated = articulated or bool(self.worked)
        self.scenery_q = dict(scenery_q or {})
        self.role_geoms: dict[str, ItemGeoms] = {}
        super().__init__(robots, fixture=fixture, part=part, **kwargs)

    # the fixture's part is the task's articulation only when the task works it
    @property
    def part(self) -> str:
        return self._part if self.articulated else ""

    @part.setter
    def part(self, value: str) -> None:
        self._part = value

    # ------------------------------------------------------------ worked parts
    @property
    def part_keys(self) -> tuple[str, ...]:
        """Keys of the worked parts in order (empty: the task works at most one part)."""
        return tuple(w.key for w in self.worked)

    def worked_part(self, key: str) -> WorkedPart:
        for w in self.worked:
            if w.key == key:
                return w
        raise KeyError(f"no worked part {key!r} (parts: {list(self.part_keys)})")

    @contextmanager
    def working(self, key: str) -> Iterator[None]:
        """Make worked part `key` the env's joint inside the block (`joint_value`,
        `progress`, `site_at`, `reached`, `opening`, `pressed`, `part` read it)."""
        w = self.worked_part(key)
        saved = {a: getattr(self, a) for a in (*_ACTIVE, *_MOTION)}
        name, jid, addr = self._part_joints[w.part]
        joint = FIXTURES[self.fixture_name].joints[w.part]
        values = (w.part, w.facts_as, joint, name, jid, addr, w.start_q, w.target, w.reach)
        try:
            for a, v in zip((*_ACTIVE, *_MOTION), values, strict=True):
                setattr(self, a, v)
            yield
        finally:
            for a, v in saved.items():
                setattr(self, a, v)

    def reached_part(self, key: str) -> bool:
        """Whether worked part `key` has gone (nearly) all the way to its target (and,
        for a `WorkedPart.with_items` entry, every item rests in its goal)."""
        if self.worked_part(key).with_items and not all(
            self.object_in_goal(r.name) for r in self.roles
        ):
            return False
        with self.working(key):
            return bool(self.reached())

    # ---------------------------------------------------------------- model
    def _load_model(self) -> None:
        super()._load_model()
        self.free_items = {}
        for r in self.roles:
            # a pan is the one-handle pan of `rover.sim.kitchen.pan` (fits the sink basin)
            pan = r.category == "pan"
            obj = build_pan_item(r.prefix) if pan else build_item(r.category, r.prefix)
            first = instances(r.category)[0]
            if any(i.shape in ("box", "pan") for i in instances(r.category)):
                # (round ones compile to an unturned frame at the origin as they are;
                # an explicit frame there would still change the solver's compiled
                # weights: ArrangeVegetables' expert went from 18/20 to 17/20)
                own_inertial_frame(obj, *(pan_mass_inertia if pan else mass_inertia)(first))
            self.free_items[r.name] = obj
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
        self._part_joints = {}  # fixture part -> (joint name, id, qpos address)
        for w in self.worked:
            joint = self.fixture.naming_prefix + FIXTURES[self.fixture_name].joints[w.part]
            jid = m.joint_name2id(joint)
            self._part_joints[w.part] = (joint, jid, m.get_joint_qpos_addr(joint))

    # ---------------------------------------------------------------- reset
    def _reset_internal(self) -> None:
        super()._reset_internal()
        base = {k: getattr(self.scene, k) for k in Scene.__dataclass_fields__}
        objects, board = self._draw_composite()
        base["decor"] = clear_decor(base["decor"], objects)
        self.scene = CompositeScene(**base, objects=objects, board=board)
        self.apply_scene(self.scene)
        d = self.sim.data
        for obj in objects:
            a, b = self.role_qpos[obj["role"]]
            d.qpos[a:b] = obj["qpos"]
            dof = self.role_dof[obj["role"]]
            d.qvel[dof : dof + 6] = 0.0
        m = self.sim.model
        for part, q in self.scenery_q.items():
            joint = self.fixture.naming_prefix + FIXTURES[self.fixture_name].joints[part]
            d.qpos[m.get_joint_qpos_addr(joint)] = q
            d.qvel[int(m._model.jnt_dofadr[m.joint_name2id(joint)])] = 0.0
        started: set[str] = set()
        for w in self.worked:  # each worked joint at its first entry's start
            if w.part not in started:
                started.add(w.part)
                _, jid, addr = self._part_joints[w.part]
                d.qpos[addr] = w.start_q
                d.qvel[int(m._model.jnt_dofadr[jid])] = 0.0
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
            (x0, x1), (y0, y1) = START_SPOTS.get(role.start) or BESIDE_SPOTS[role.start]
            x, y = float(rng.uniform(x0, x1)), float(rng.uniform(y0, y1))
            if role.start in BESIDE_SPOTS:  # y from the fixture's +y edge along the counter
                y += self.scene.layout[self.fixture_name].y + FIXTURES[self.fixture_name].half_width
            yaw = float(rng.uniform(*START_YAW.get(role.start, (-np.pi, np.pi))))
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
            inst = instance_named(obj["name"])
            bid = self.role_body_ids[name]
            weigh = pan_mass_inertia if inst.category == "pan" else mass_inertia
            m.body_mass[bid], m.body_inertia[bid] = weigh(inst)
            if inst.category == "pan":  # the handle and floor sites of the drawn pan
                prefix = self.free_items[name].naming_prefix
                for site, pos in site_positions(inst).items():
                    m.site_pos[self.sim.model.site_name2id(prefix + site)] = pos
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
        pan = self._pan_holding(name, centre, bottom)
        if pan is not None:
            return pan
        if self.board_body_id is not None:
            d = self.sim.data._data
            origin = d.xpos[self.board_body_id]
            yaw = float(self.scene.board["yaw"])
            local = to_local(centre, origin, yaw)
            if BOARD_REGION.holds(local, bottom - origin[2]):
                return "on", BOARD_REGION.name
        return locate(centre, bottom, self.fixture_poses())

    def _pan_holding(self, name: str, centre, bottom: float) -> tuple[str, str] | None:
        """("inside", "pan") when item `name` rests in another item that is a pan (the
        region moves with the pan: its floor in the pan's own frame)."""
        for obj in self.scene.objects:
            if obj["category"] != "pan" or obj["role"] == name:
                continue
            d = self.sim.data._data
            bid = self.role_body_ids[obj["role"]]
            rot = d.xmat[bid].reshape(3, 3)
            local = rot.T @ (np.asarray(centre) - d.xpos[bid])
            low = bottom - d.xpos[bid][2]  # the pan stands level: height is z
            inst = instance_named(obj["name"])
            if PAN_REGION.holds(inst, local, low):
                return "inside", PAN_REGION.name
        return None

    def object_in_goal(self, name: str) -> bool:
        found = self.object_place(name)
        return found is not None and found[1] == self.role(name).goal

    def _check_success(self) -> bool:
        if not self.roles:
            return super()._check_success()
        done = all(self.object_in_goal(r.name) for r in self.roles)
        if self.worked:  # every worked joint where its last entry takes it
            last = {w.facts_as: w.key for w in self.worked}
            return done and all(self.reached_part(k) for k in last.values())
        return done and (not self.articulated or bool(self.reached()))
