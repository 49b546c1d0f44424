"""`RoverKitchen`: a Panda at a kitchen counter with every kitchen fixture, one of them in use.

The model is built once per process (the same for every seed, so saved states fit any
process); each reset draws a `Scene` from the env's seeded generator and applies it to
the model in place: fixture poses along the counter, which robosuite texture each
surface shows, robosuite's `LightingModder` and `CameraModder` for light and camera
jitter, and the décor instances on the counter. The task's articulated part (a drawer
slide, a door hinge, a button, a knob) is exposed through `FixtureEnv`'s interface, so
the articulation facts, predicates, goals and the scripted experts of the tabletop
fixtures work here unchanged.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import robosuite
from robosuite.environments.manipulation.manipulation_env import ManipulationEnv
from robosuite.models.arenas import TableArena
from robosuite.models.tasks import ManipulationTask
from robosuite.utils.mjmod import CameraModder, LightingModder

from rover.sim.fixtures.base import FixtureEnv, FixtureObject
from rover.sim.fixtures.button import PRESS_Q
from rover.sim.fixtures.drawer import OPEN_Q
from rover.sim.kitchen.fixtures import COUNTER_SIZE, COUNTER_TOP, FIXTURES, narrow_fixture
from rover.sim.kitchen.forward_grasp import READY_Q
from rover.sim.kitchen.items import ItemGeoms, build_item, mass_inertia
from rover.sim.kitchen.objects import CATALOGUE, build_object, draw_decor, half_height, make_static
from rover.sim.kitchen.placement import draw_item, item_bottom, item_place
from rover.sim.kitchen.regions import OPENINGS
from rover.sim.kitchen.scene import TEXTURES, Scene, draw_scene, draw_style

TEXTURE_DIR = Path(robosuite.__file__).resolve().parent / "models" / "assets" / "textures"
HIDDEN_X = 6.0  # m: unused fixtures stand on the floor outside the room's walls
HIDDEN_Z = -3.0  # m: unused décor (welded, so it touches nothing) waits below the floor
LIGHT = "kitchen_light"
COUNTER_GOAL = "kitchen_counter_goal"  # site: the counter spot a pick-and-place item goes to
# the kitchen's two workspace cameras (render views "left" / "right"): free-view style
# (look-at point, distance, azimuth, elevation in degrees) made into model cameras so
# robosuite's CameraModder can jitter them per scene
CAMERAS = {
    "rover_left": ((0.1, 0.0, 0.85), 1.35, -62.0, -40.0),
    "rover_right": ((0.1, 0.0, 0.85), 1.35, 62.0, -40.0),
}


def _camera_pose(lookat, distance: float, azimuth: float, elevation: float) -> tuple[str, str]:
    """MJCF ``pos`` and ``xyaxes`` of a camera placed as MuJoCo's free camera would be."""
    az, el = np.radians(azimuth), np.radians(elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    pos = np.asarray(lookat) - distance * forward
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    fmt = lambda v: " ".join(f"{x:.5f}" for x in v)  # noqa: E731
    return fmt(pos), fmt(np.concatenate([right, up]))


def _yaw_quat(yaw: float) -> list[float]:
    return [float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))]


class RoverKitchen(FixtureEnv):
    """The kitchen counter; `part` of fixture `fixture` is the task's articulation.

    Args:
        robots: robosuite robot spec.
        fixture: the kitchen fixture in use ("Microwave"; `rover.sim.kitchen.fixtures`).
        part: its articulated part ("button"); its joint becomes the env's joint.
        facts_as: the name the facts and events give that part (default `part`): the
            sink spout is read as a "knob" (turned through a fraction of its target).
        start_q, target, reach: as in `FixtureEnv` (a door to close starts open, ...).
        also_used: further fixtures placed within reach (composite tasks).
        item: category of a free item to pick and place ("vegetable"; None: no item).
            The fixture part is then only the fixture's pose (no articulation facts).
        start, goal: the item's start and goal regions (`rover.sim.kitchen.regions`).
        level_start: start the Panda in the level-hand ready pose of the forward grasp
            (`rover.sim.kitchen.forward_grasp.READY_Q`); None: when the item's start or
            goal region lies behind a fixture's opening.
        x_range, y_range, yaw_range: the task's own ranges for the fixture's origin
            (x m away from the robot, y m along the counter) and yaw (rad), inside the
            fixture's (`narrow_fixture`); None: the fixture's. MicrowaveThawing draws
            the microwave from where its expert can pull the door open
            (`rover.sim.kitchen.thawing.MICROWAVE_X`, ...).
        decor_clear: a band of counter y (m) no décor stands in: the arm's path around
            the fixture (MicrowaveThawing's hand goes round the open door's outer side,
            where a cereal box on a décor spot blocked its wrist). None: every spot.
        **kwargs: the usual `ManipulationEnv` arguments.
    """

    def __init__(
        self,
        robots,
        fixture: str = "Drawer",
        part: str = "drawer",
        facts_as: str | None = None,
        also_used: tuple[str, ...] = (),
        item: str | None = None,
        start: str = "counter",
        goal: str = "counter",
        level_start: bool | None = None,
        x_range: tuple[float, float] | list[float] | None = None,
        y_range: tuple[float, float] | list[float] | None = None,
        yaw_range: tuple[float, float] | list[float] | None = None,
        decor_clear: tuple[float, float] | list[float] | None = None,
        **kwargs,
    ) -> None:
        if fixture not in FIXTURES or part not in FIXTURES[fixture].joints:
            raise ValueError(f"kitchen fixture {fixture!r} has no part {part!r}")
        self.narrowed = {  # (without a task range, a copy equal to the fixture's own)
            fixture: narrow_fixture(fixture, x_range=x_range, y_range=y_range, yaw_range=yaw_range)
        }
        self.decor_clear = None if decor_clear is None else tuple(decor_clear)
        self.fixture_name = fixture
        self.kind = part  # the fixture's own part name (the experts read this)
        self.part = "" if item else (facts_as or part)
        self.item_category, self.item_start, self.item_goal = item, start, goal
        self.item_geoms: ItemGeoms | None = None
        if level_start is None:
            level_start = bool(item) and bool({start, goal} & set(OPENINGS))
        self.level_start = level_start
        self.joint = FIXTURES[fixture].joints[part]
        self.used = [fixture, *[f for f in also_used if f != fixture]]
        self.scene: Scene | None = None
        self._modders: tuple[LightingModder, CameraModder] | None = None
        super().__init__(robots=robots, **kwargs)
        self.table_full_size = COUNTER_SIZE

    def opening(self) -> float:
        """How far open, 0 closed: a drawer 1 pulled out `OPEN_Q` or more (as the
        tabletop's); a hinged door 1 at the open end of its task's swing (the target when
        opening it, the start when closing it), so "x% open" reads the same both ways."""
        full = OPEN_Q if self.kind == "drawer" else max(self.start_q, self.target)
        return float(np.clip(self.joint_value() / full, 0.0, 1.0))

    def pressed(self) -> bool:
        """Button: pushed down past the switching depth (the appliance is on)."""
        return self.joint_value() <= PRESS_Q

    # ---------------------------------------------------------------- model
    def _load_model(self) -> None:
        ManipulationEnv._load_model(self)
        if self.level_start:  # robosuite's reset puts the arm here, the OSC posture with it
            self.robots[0].init_qpos = np.array(READY_Q)
        self.table_full_size = COUNTER_SIZE
        self.table_offset = np.array((0.0, 0.0, COUNTER_TOP))
        xpos = self.robots[0].robot_model.base_xpos_offset["table"](COUNTER_SIZE[0])
        self.robots[0].robot_model.set_base_xpos(xpos)
        arena = TableArena(table_full_size=COUNTER_SIZE, table_offset=self.table_offset)
        arena.set_origin([0, 0, 0])
        self._dress_arena(arena)
        self.fixtures = {n: FixtureObject(n, str(f.xml)) for n, f in FIXTURES.items()}
        self.fixture = self.fixtures[self.fixture_name]
        self.decor = {}
        for inst in CATALOGUE:
            obj = build_object(inst)
            make_static(obj)
            self.decor[inst.name] = obj
        self.item = build_item(self.item_category) if self.item_category else None
        self.model = ManipulationTask(
            mujoco_arena=arena,
            mujoco_robots=[robot.robot_model for robot in self.robots],
            mujoco_objects=[*self.fixtures.values(), *self.decor.values()]
            + ([self.item] if self.item is not None else []),
        )
        # a fixture's case is welded to the world, so MuJoCo's parent-child filter does not
        # keep its moving parts (a button sinking into the roof, a knob on its deck) from
        # colliding with it: exclude those pairs explicitly
        for obj in self.fixtures.values():
            case = obj.root_body
            for body in obj.get_obj().iter("body"):
                if body.find("joint") is not None:
                    ET.SubElement(self.model.contact, "exclude", body1=case, body2=body.get("name"))

    def _dress_arena(self, arena: TableArena) -> None:
        """Backsplash, a named light, the two cameras and one material per texture choice."""
        ET.SubElement(
            arena.worldbody,
            "geom",
            name="backsplash",
            type="box",
            pos=f"{COUNTER_SIZE[0] / 2 + 0.01} 0 {COUNTER_TOP + 0.45}",
            size=f"0.01 {COUNTER_SIZE[1] / 2} 0.45",
            group="1",
            contype="0",
            conaffinity="0",
            material="walls_mat",
        )
        ET.SubElement(
            arena.worldbody,
            "site",
            name=COUNTER_GOAL,
            pos=f"0 0 {COUNTER_TOP}",
            size="0.005",
            rgba="0 0 0 0",
            group="4",
        )
        light = arena.worldbody.find("light")
        light.set("name", LIGHT)
        for name, view in CAMERAS.items():
            pos, axes = _camera_pose(*view)
            ET.SubElement(arena.worldbody, "camera", name=name, mode="fixed", pos=pos, xyaxes=axes)
        made: set[str] = set()
        for surface, names in TEXTURES.items():
            kind = "2d" if surface in ("floor", "wall") else "cube"
            for tex in names:
                tid = f"rk_{kind}_{tex}"
                if tid not in made:
                    file = str(TEXTURE_DIR / f"{tex}.png")
                    ET.SubElement(arena.asset, "texture", name=tid, type=kind, file=file)
                    made.add(tid)
                attrs = {"name": f"rk_{surface}_{tex}", "texture": tid, "specular": "0.1"}
                if kind == "2d":
                    attrs.update(texrepeat="3 3" if surface == "wall" else "2 2", texuniform="true")
                ET.SubElement(arena.asset, "material", **attrs)

    def _setup_references(self) -> None:
        ManipulationEnv._setup_references(self)
        m = self.sim.model
        self.fixture_body_ids = {n: m.body_name2id(o.root_body) for n, o in self.fixtures.items()}
        self.fixture_body_id = self.fixture_body_ids[self.fixture_name]
        self.joint_name = self.fixture.naming_prefix + self.joint
        self.joint_id = m.joint_name2id(self.joint_name)
        self.joint_qpos_addr = m.get_joint_qpos_addr(self.joint_name)
        self.decor_body_ids = {n: m.body_name2id(o.root_body) for n, o in self.decor.items()}
        self.counter_goal_site = m.site_name2id(COUNTER_GOAL)
        if self.item is not None:
            self.item_body_id = m.body_name2id(self.item.root_body)
            self.item_qpos_addr = m.get_joint_qpos_addr(self.item.joints[0])
            if self.item_geoms is None:  # once: later calls see a scene's switched geoms
                self.item_geoms = ItemGeoms.of(m._model, self.item_category)
        names = [m.geom_id2name(g) or "" for g in range(m.ngeom)]
        self.decor_geoms = {
            n: [g for g in range(m.ngeom) if names[g].startswith(o.naming_prefix)]
            for n, o in self.decor.items()
        }
        surfaces: dict[str, list[int]] = {"floor": [], "wall": [], "counter": [], "wood": []}
        for g, name in enumerate(names):
            if name == "floor":
                surfaces["floor"].append(g)
            elif name.startswith("wall_") or name == "backsplash":
                surfaces["wall"].append(g)
            elif name == "table_visual":
                surfaces["counter"].append(g)
        for fname, fx in FIXTURES.items():
            pre = self.fixtures[fname].naming_prefix
            wanted = {f"{pre}{w}_visual" for w in fx.wood} | {f"{pre}{w}" for w in fx.wood}
            surfaces["wood"] += [
                g for g, name in enumerate(names) if name in wanted and m.geom_group[g] == 1
            ]
        self.surface_geoms = surfaces
        self.material_ids = {
            (s, t): mujoco.mj_name2id(m._model, mujoco.mjtObj.mjOBJ_MATERIAL, f"rk_{s}_{t}")
            for s, ts in TEXTURES.items()
            for t in ts
        }

    # ---------------------------------------------------------------- reset
    def _reset_internal(self) -> None:
        ManipulationEnv._reset_internal(self)
        decor = draw_decor(self.rng, self.decor_clear)
        self.scene = draw_scene(self.rng, self.used, decor, self.narrowed)
        if self.item is not None:
            self.scene.item = draw_item(self.rng, self)
        self.apply_scene(self.scene)
        self.sim.data.qpos[self.joint_qpos_addr] = self.start_q
        self.sim.data.qvel[self.model_dof_addr()] = 0.0
        if self.item is not None:  # the item at rest in its start region
            a, b = self.item_qpos_addr
            self.sim.data.qpos[a:b] = self.scene.item["qpos"]
            dof = int(
                self.sim.model._model.jnt_dofadr[self.sim.model.joint_name2id(self.item.joints[0])]
            )
            self.sim.data.qvel[dof : dof + 6] = 0.0
        self.sim.forward()

    def restyle(self, seed: int) -> None:
        """Redraw this scene's look (textures, light, camera) from `seed`; layout stays.

        The generator calls it per episode, so episodes replaying one demonstration
        (same layout, same physics) still show different kitchens.
        """
        if self.scene is None:
            raise RuntimeError("restyle before the first reset")
        style = draw_style(np.random.default_rng([int(seed), 0x5C3E]))
        self.scene = replace(self.scene, **style)
        self.apply_scene(self.scene)

    def apply_scene(self, scene: Scene) -> None:
        """Pose fixtures and décor, switch surface materials, jitter light and cameras."""
        m = self.sim.model
        for k, (name, bid) in enumerate(self.fixture_body_ids.items()):
            place = scene.layout.get(name)
            if place is None:
                m.body_pos[bid] = [HIDDEN_X, 1.0 * k, 0.0]
                m.body_quat[bid] = [1.0, 0.0, 0.0, 0.0]
                continue
            m.body_pos[bid] = [place.x, place.y, COUNTER_TOP]
            m.body_quat[bid] = _yaw_quat(place.yaw)
        shown = {d["name"]: d for d in scene.decor}
        for inst in CATALOGUE:
            bid, d = self.decor_body_ids[inst.name], shown.get(inst.name)
            if d is None:
                m.body_pos[bid] = [0.0, 0.0, HIDDEN_Z]
                continue
            m.body_pos[bid] = [d["x"], d["y"], COUNTER_TOP + half_height(inst)]
            m.body_quat[bid] = _yaw_quat(d["yaw"])
            for g in self.decor_geoms[inst.name]:
                m.geom_rgba[g][:3] = d["rgb"]
        if self.item is not None and scene.item is not None:
            self._apply_item(scene.item)
        for surface, geoms in self.surface_geoms.items():
            mat = self.material_ids[(surface, scene.textures[surface])]
            for g in geoms:
                m.geom_matid[g] = mat
                m.geom_rgba[g] = [0.5, 0.5, 0.5, 1.0]  # MuJoCo's default: show the material
        if self._modders is None:
            self._modders = (
                LightingModder(
                    self.sim,
                    light_names=[LIGHT],
                    randomize_active=False,
                    position_perturbation_size=0.5,
                    direction_perturbation_size=0.25,
                    specular_perturbation_size=0.05,
                    ambient_perturbation_size=0.08,
                    diffuse_perturbation_size=0.15,
                ),
                CameraModder(
                    self.sim,
                    camera_names=list(CAMERAS),
                    position_perturbation_size=0.03,
                    rotation_perturbation_size=0.04,
                    randomize_fovy=False,
                ),
            )
        lights, cams = self._modders
        for modder, seed in ((lights, scene.light_seed), (cams, scene.camera_seed)):
            modder.restore_defaults()
            modder.random_state = np.random.RandomState(seed)
            modder.randomize()
        self.sim.forward()

    # ---------------------------------------------------------- pick and place
    def _apply_item(self, item: dict) -> None:
        """Show the drawn instance (geoms, colour, mass) and put the counter goal spot."""
        m = self.sim.model._model
        self.item_geoms.show(m, item["name"], item["rgb"])
        mass, inertia = mass_inertia(self.item_instance())
        m.body_mass[self.item_body_id] = mass
        m.body_inertia[self.item_body_id] = inertia
        m.body_ipos[self.item_body_id] = 0.0
        m.body_iquat[self.item_body_id] = [1.0, 0.0, 0.0, 0.0]
        m.site_pos[self.counter_goal_site] = [*item["counter"], COUNTER_TOP]

    def item_instance(self):
        """The catalogue `Instance` this scene's item is."""
        from rover.sim.kitchen.forward_items import instance_named

        return instance_named(self.scene.item["name"])

    def fixture_poses(self) -> dict[str, tuple[np.ndarray, float]]:
        """Fixture name -> (origin, yaw) of every fixture standing on the counter."""
        out = {}
        for name, place in self.scene.layout.items():
            if place is not None:
                out[name] = (np.array([place.x, place.y, COUNTER_TOP]), place.yaw)
        return out

    def item_place(self) -> tuple[str, str] | None:
        """(relation, region) the item rests in now ("inside", "sink"), or None."""
        if self.item is None or self.scene is None:
            return None
        return item_place(self)

    def item_in_goal(self) -> bool:
        """The item rests in its goal region (touched or not)."""
        found = self.item_place()
        return found is not None and found[1] == self.item_goal

    def _check_success(self) -> bool:
        if self.item is not None:  # pick and place: the item rests in its goal region
            return self.item_in_goal()
        return super()._check_success()

    def item_bottom(self) -> float:
        return item_bottom(self)
