"""robosuite environment wrapper: the `SimAdapter` the trajectory and value code drive.

One `SimEnv` per task per process. It builds the robosuite environment without any
camera or renderer (simulation runs at full rate; frames are rendered later from saved
states by `rover.sim.render`), reseeds it per episode, and answers the named points and
predicates a `TaskSpec` mentions, reading MuJoCo data directly so that any saved state
can be measured again after `set_state`.
"""

from __future__ import annotations

import logging
import os

import mujoco
import numpy as np

from rover.errors import InputError, MissingExtraError
from rover.sim import articulation
from rover.sim.interp import interpolate_state
from rover.sim.tasks.base import TaskSpec

CONTROL_FREQ = 20  # Hz; the expert and every deviation step run at this rate
LIFT_HEIGHT = 0.04  # m above its start height for an object to count as lifted
SETTLE_STEPS = 200  # physics steps (0.4 s) a start position is let fall for, robot held


def _import_robosuite():
    os.environ.setdefault("MUJOCO_GL", "egl")
    # robosuite logs set-up advice (private macro file, optional robot packages) at
    # import; none of it applies here, so keep it off the user's console
    logging.disable(logging.WARNING)
    try:
        import robosuite
        from robosuite.controllers import load_composite_controller_config
    except ImportError as exc:  # pragma: no cover - depends on the install
        raise MissingExtraError("robosuite", "sim", "simulated benchmark generation") from exc
    finally:
        logging.disable(logging.NOTSET)
    for name in ("robosuite", "robosuite_logs"):
        logging.getLogger(name).setLevel(logging.ERROR)
    return robosuite, load_composite_controller_config


def make_robosuite_env(env_name: str, env_kwargs: dict | None = None):
    """Build a camera-less Panda + OSC_POSE robosuite environment (fast to step)."""
    suite, load_cfg = _import_robosuite()
    if env_name.startswith("Rover"):  # rover's own fixtures register on import
        import rover.sim.fixtures  # noqa: F401
    controller = load_cfg(controller="BASIC", robot="Panda")
    kwargs = dict(
        robots="Panda",
        controller_configs=controller,
        has_renderer=False,
        has_offscreen_renderer=False,
        use_camera_obs=False,
        hard_reset=False,
        control_freq=CONTROL_FREQ,
        horizon=100_000,
        ignore_done=True,
        reward_shaping=False,
        # the model itself is randomised at construction (Lift's and Stack's cube sizes):
        # a fixed seed gives every process the same model, so saved states fit everywhere
        seed=0,
    )
    kwargs.update(env_kwargs or {})
    return suite.make(env_name, **kwargs)


class SimEnv:
    """A robosuite task behind the `SimAdapter` protocol, plus facts the generator needs."""

    def __init__(self, spec: TaskSpec) -> None:
        self.spec = spec
        self.env = make_robosuite_env(spec.env_name, spec.env_kwargs)
        self.sim = self.env.sim
        self.model: mujoco.MjModel = self.sim.model._model
        self.data: mujoco.MjData = self.sim.data._data
        low, high = self.env.action_spec
        self.action_low = np.asarray(low, dtype=np.float64)
        self.action_high = np.asarray(high, dtype=np.float64)
        self._robot = self.env.robots[0]
        self._gripper = self._robot.gripper["right"]
        self._eef_site = self._robot.eef_site_id["right"]
        self._finger_geoms = {
            side: [self._geom_id(g) for g in self._gripper.important_geoms[f"{side}_finger"]]
            for side in ("left", "right")
        }
        self._pad_geoms = {
            side: self._geom_id(self._gripper.important_geoms[f"{side}_fingerpad"][0])
            for side in ("left", "right")
        }
        fj = [self.model.joint(j) for j in self._gripper.joints]
        self._finger_qpos = [int(j.qposadr[0]) for j in fj]
        self._geom_owner = self._object_geoms()
        self._robot_geoms = self._subtree_geoms(self._robot.robot_model.root_body)
        self.robot_qpos, self.robot_qvel = self._subtree_dofs(self._robot.robot_model.root_body)
        self.start_positions: dict[str, np.ndarray] = {}

    # ----------------------------------------------------------------- set-up
    def _geom_id(self, name: str) -> int:
        return int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_GEOM, name))

    def _body_id(self, name: str) -> int:
        bid = int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name))
        if bid < 0:
            raise KeyError(f"no body {name!r} in {self.spec.env_name}")
        return bid

    def _object_geoms(self) -> dict[int, str]:
        """geom id -> object name, for every geom in each object's body subtree."""
        owner: dict[int, str] = {}
        parents = self.model.body_parentid
        for obj in self.spec.objects:
            root = self._body_id(obj.body)
            for g in range(self.model.ngeom):
                b = int(self.model.geom_bodyid[g])
                while b != 0 and b != root:
                    b = int(parents[b])
                if b == root:
                    owner[g] = obj.name
        return owner

    def _in_subtree(self, body: int, root: int) -> bool:
        parents = self.model.body_parentid
        while body != 0 and body != root:
            body = int(parents[body])
        return body == root

    def _subtree_geoms(self, root_name: str) -> set[int]:
        root = self._body_id(root_name)
        return {
            g
            for g in range(self.model.ngeom)
            if self._in_subtree(int(self.model.geom_bodyid[g]), root)
        }

    def _subtree_dofs(self, root_name: str) -> tuple[np.ndarray, np.ndarray]:
        """Flat-state indices (after the time entry) of the qpos and qvel of a subtree's joints:
        the robot's arm and fingers, which a recovery may interpolate."""
        root = self._body_id(root_name)
        qpos: list[int] = []
        qvel: list[int] = []
        sizes = {0: (7, 6), 1: (4, 3), 2: (1, 1), 3: (1, 1)}  # free, ball, slide, hinge
        for j in range(self.model.njnt):
            if not self._in_subtree(int(self.model.jnt_bodyid[j]), root):
                continue
            nq, nv = sizes[int(self.model.jnt_type[j])]
            qa, va = int(self.model.jnt_qposadr[j]), int(self.model.jnt_dofadr[j])
            qpos += range(qa, qa + nq)
            qvel += range(va, va + nv)
        return np.asarray(qpos, dtype=np.int64), np.asarray(qvel, dtype=np.int64)

    def reset(self, seed: int) -> np.ndarray:
        """Reset to the initial configuration drawn from `seed`; return the flat state."""
        self.env.rng.bit_generator.state = np.random.default_rng(seed).bit_generator.state
        self.env.reset()
        if self.spec.clear_objects:
            self.env.clear_objects(self.spec.clear_objects)
        # start with the fingers wide open (robosuite starts them half open, which would
        # read as "closed" in the facts before the first gripper command)
        self.data.qpos[self._finger_qpos[0]] = 0.04
        self.data.qpos[self._finger_qpos[1]] = -0.04
        self.data.qacc_warmstart[:] = 0.0
        self.sim.forward()
        self.start_positions = self._rest_positions()
        return self.get_state()

    def begin(self, state: np.ndarray) -> None:
        """Start an episode at a saved state (a demo's first state): objects' start
        positions, which lift heights and some goals are measured from, come from it."""
        state = np.asarray(state, dtype=np.float64)
        if state.shape != self.get_state().shape:
            raise InputError(
                f"{self.spec.name}: a state of length {state.shape[0]} does not fit this "
                f"environment (expected {self.get_state().shape[0]}); wrong --source-hdf5?"
            )
        self.set_state(state)
        self.start_positions = self._rest_positions()

    def _rest_positions(self) -> dict[str, np.ndarray]:
        """Where each task object comes to rest from the current state, the robot held
        still (the state is restored). "Lifted" and "on the table" are measured from an
        object's start, and robosuite drops some objects into the scene: NutAssembly's
        nuts appear 6 cm above the table and fall in a demo's first steps, so a nut had
        to be 10 cm off the table to count as lifted and never read as on it."""
        saved = self.get_state()
        qpos, qvel = self.robot_qpos, self.robot_qvel
        hold_q, hold_v = self.data.qpos[qpos].copy(), self.data.qvel[qvel].copy()
        try:
            for _ in range(SETTLE_STEPS):
                mujoco.mj_step(self.model, self.data)
                self.data.qpos[qpos], self.data.qvel[qvel] = hold_q, hold_v
            return {o.name: self.point(o.name).copy() for o in self.spec.objects}
        finally:
            self.set_state(saved)

    # ------------------------------------------------------------ SimAdapter
    def get_state(self) -> np.ndarray:
        return np.asarray(self.sim.get_state().flatten(), dtype=np.float64)

    def set_state(self, state: np.ndarray) -> None:
        self.sim.set_state_from_flattened(np.asarray(state, dtype=np.float64))
        # the solver's warm start is not part of the state: clear it so stepping from a
        # restored state is the same whatever ran before (determinism for a seed)
        self.data.qacc_warmstart[:] = 0.0
        self.sim.forward()

    def step(self, action: np.ndarray) -> None:
        self.env.step(np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0))

    def interpolate(self, a: np.ndarray, b: np.ndarray, alpha: float) -> np.ndarray:
        return interpolate_state(self.model, a, b, alpha)

    def drive_robot(self, a: np.ndarray, b: np.ndarray, alpha0: float, alpha1: float) -> None:
        """One recovery step with physics: the robot's joints follow the interpolation
        from state `a` to state `b` (fraction alpha0 -> alpha1) over one control step,
        and everything else (free objects, doors, drawers) is simulated, so an object moves
        only if the robot pushes or carries it, or gravity does. Starts from the current
        state; no object is ever set to a pose physics did not reach."""
        qa = a[1 + self.robot_qpos]
        qb = b[1 + self.robot_qpos]
        substeps = max(1, int(round(self.env.control_timestep / self.model.opt.timestep)))
        dt = self.env.control_timestep
        vel = (qb - qa) * (alpha1 - alpha0) / dt
        d = self.data
        for k in range(1, substeps + 1):
            t = alpha0 + (alpha1 - alpha0) * k / substeps
            d.qpos[self.robot_qpos] = (1.0 - t) * qa + t * qb
            d.qvel[self.robot_qvel] = vel
            mujoco.mj_step(self.model, d)
        d.qpos[self.robot_qpos] = (1.0 - alpha1) * qa + alpha1 * qb
        d.qvel[self.robot_qvel] = vel
        self.sim.forward()

    def entity_positions(self) -> np.ndarray:
        pts = [self.point("eef")] + [self.point(o.name) for o in self.spec.objects]
        return np.stack(pts)

    def point(self, name: str) -> np.ndarray:
        d = self.data
        if name == "eef":
            return d.site_xpos[self._eef_site].copy()
        if name in ("left_finger", "right_finger"):
            return d.geom_xpos[self._pad_geoms[name.split("_")[0]]].copy()
        if name.startswith("goal:"):
            return self.goal(name[5:])
        if name.startswith("joint:"):  # a scalar carried in x: fraction of the way to the goal
            return np.array([self.joint_fraction(name[6:]), 0.0, 0.0])
        obj_name, _, site = name.partition(":")
        obj = self.spec.object_spec(obj_name)
        if site:
            return self._named_xpos(obj.sites[site])
        return self._named_xpos(obj.centre or obj.body)

    def _named_xpos(self, name: str) -> np.ndarray:
        sid = int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, name))
        if sid >= 0:
            return self.data.site_xpos[sid].copy()
        return self.data.xpos[self._body_id(name)].copy()

    def success(self) -> bool:
        return all(self.predicate(s.end_signal) for s in self.spec.subtasks[-1:]) and all(
            self.predicate(s) for s in self._final_signals()
        )

    def _final_signals(self) -> list[str]:
        """Earlier subtasks whose result must still hold at the end: an item placed, a
        door shut (MicrowaveThawing shuts the door before pressing start; a door pulled
        ajar again on the way to the button is not a finished task)."""
        return [
            s.end_signal
            for s in self.spec.subtasks
            if s.end_signal.startswith(("placed:", "door_closed:"))
        ]

    # ------------------------------------------------------------------ goals
    def goal(self, name: str) -> np.ndarray:
        g = self.spec.goals[name]
        off = np.asarray(g.offset, dtype=np.float64)
        if g.kind == "bin":
            idx = self.spec.bins[g.object]
            return np.asarray(self.env.target_bin_placements[idx], dtype=np.float64) + off
        if g.kind == "above":
            return self.point(g.object) + off
        if g.kind == "body":
            return self._named_xpos(g.body) + off
        if g.kind == "start_offset":
            return self.start_positions[g.object] + off
        if g.kind == "door_open":
            return self._door_handle_at(g.angle)
        if g.kind == "fixture":
            return articulation.goal(self, g)
        raise ValueError(f"unknown goal kind {g.kind}")

    def _door_handle_at(self, angle: float) -> np.ndarray:
        """Where the handle would be with the door hinge at `angle` radians."""
        jid = self._hinge_joint()
        anchor, axis = self.data.xanchor[jid], self.data.xaxis[jid]
        handle = self.point("door:handle")
        rot = angle - self.hinge_angle()
        v = handle - anchor
        k = axis / np.linalg.norm(axis)
        v_rot = (
            v * np.cos(rot) + np.cross(k, v) * np.sin(rot) + k * np.dot(k, v) * (1 - np.cos(rot))
        )
        return anchor + v_rot

    def _hinge_joint(self) -> int:
        return int(
            mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, self.env.door.joints[0])
        )

    def hinge_angle(self) -> float:
        return float(self.data.qpos[self.env.hinge_qpos_addr])

    # ----------------------------------------------------- contacts, gripper
    def finger_contacts(self) -> dict[str, set[str]]:
        """Object name -> the fingers ("left"/"right") touching it; robot body excluded."""
        out: dict[str, set[str]] = {}
        fingers = {g: side for side, gs in self._finger_geoms.items() for g in gs}
        for i in range(self.data.ncon):
            g1, g2 = int(self.data.contact[i].geom1), int(self.data.contact[i].geom2)
            for a, b in ((g1, g2), (g2, g1)):
                if a in fingers and b in self._geom_owner:
                    out.setdefault(self._geom_owner[b], set()).add(fingers[a])
        return out

    def robot_contacts(self) -> set[str]:
        """Objects any part of the robot (arm, hand or fingers) touches now."""
        out: set[str] = set()
        for i in range(self.data.ncon):
            g1, g2 = int(self.data.contact[i].geom1), int(self.data.contact[i].geom2)
            for a, b in ((g1, g2), (g2, g1)):
                if a in self._robot_geoms and b in self._geom_owner:
                    out.add(self._geom_owner[b])
        return out

    def eef_frame(self) -> tuple[np.ndarray, np.ndarray]:
        """The end effector's position and rotation matrix (world frame)."""
        return (
            self.data.site_xpos[self._eef_site].copy(),
            self.data.site_xmat[self._eef_site].reshape(3, 3).copy(),
        )

    def gripper_opening(self) -> float:
        """0 = fingers fully closed, 1 = fully open (Panda: 0.08 m between fingers)."""
        q = self.data.qpos
        width = abs(q[self._finger_qpos[0]]) + abs(q[self._finger_qpos[1]])
        return float(np.clip(width / 0.08, 0.0, 1.0))

    # ------------------------------------------------------------- predicates
    def grasped(self, obj: str) -> bool:
        touching = self.finger_contacts().get(obj, set())
        return touching == {"left", "right"}

    def lifted(self, obj: str) -> bool:
        start = self.start_positions.get(obj)
        if start is None:
            return False
        return bool(self.point(obj)[2] - start[2] > LIFT_HEIGHT)

    def in_bin(self, obj: str) -> int | None:
        """PickPlace compartment index the object rests in (robosuite's test), if any."""
        pos = self.point(obj)
        for i in range(4):
            if not self.env.not_in_bin(pos, i):
                return i
        return None

    def predicate(self, signal: str) -> bool:
        """Evaluate an end-of-subtask signal such as ``"lifted:can"`` in the current state."""
        kind, _, obj = signal.partition(":")
        if kind == "grasped":
            return self.grasped(obj)
        if kind == "lifted":
            return self.lifted(obj) and self.grasped(obj)
        if kind == "placed" and hasattr(self.env, "object_in_goal"):  # a kitchen composite
            return self.env.object_in_goal(obj) and not self.grasped(obj)
        if kind == "placed" and "region" in self.spec.goals:  # a kitchen goal region
            return self.env.item_in_goal() and not self.grasped(obj)
        if kind == "placed":
            return self.in_bin(obj) == self.spec.bins[obj] and not self.grasped(obj)
        if kind == "stacked":
            below = self.spec.goals["on"].object
            return self.on_top(obj, below) and not self.grasped(obj)
        if kind == "opened":
            return self.hinge_angle() > self.spec.goals["door_open"].angle * 0.9
        if kind == "on_peg":
            return self.on_peg(obj) and not self.grasped(obj)
        found = articulation.predicate(self, kind, obj)
        if found is not None:
            return found
        raise ValueError(f"unknown end signal {signal!r}")

    def joint_fraction(self, obj: str) -> float:
        """How far an articulated object's joint has gone toward its goal, 0..1 (door
        hinge, drawer slide, button travel, knob turn)."""
        if obj == "door" and "door_open" in self.spec.goals:
            return float(np.clip(self.hinge_angle() / self.spec.goals["door_open"].angle, 0, 1))
        fx = articulation.fixture(self)
        if fx is None:
            raise ValueError(f"{self.spec.name}: {obj!r} has no joint")
        return articulation.progress(self, obj)  # (several worked parts: the one named)

    def kept(self, signal: str) -> bool:
        """Whether a subtask's achievement still stands in this state (for progress).

        Looser than `predicate`, which marks the moment a subtask ends: a grasp stands
        while any finger touches the object, a placement while the object lies in its
        goal (touched or not); pressing a button or touching it cannot be undone. A
        pick-up ("lifted") stands while both fingers hold the object, or while it is
        still off its start with a finger on it: one finger brushing an object set back
        on the table is not a pick-up (such endings were valued as carried, at 0.50).
        """
        kind, _, obj = signal.partition(":")
        if kind == "lifted":
            touching = self.finger_contacts().get(obj, set())
            return touching == {"left", "right"} or (bool(touching) and self.lifted(obj))
        if kind == "grasped":
            return obj in self.finger_contacts()
        if kind == "placed" and hasattr(self.env, "object_in_goal"):
            return self.env.object_in_goal(obj)
        if kind == "placed" and "region" in self.spec.goals:
            return self.env.item_in_goal()
        if kind == "placed":
            return self.in_bin(obj) == self.spec.bins[obj]
        if kind == "stacked":
            return self.on_top(obj, self.spec.goals["on"].object)
        if kind == "on_peg":
            return self.on_peg(obj)
        if kind in ("pressed", "touched"):
            return True
        return self.predicate(signal)

    def on_top(self, obj: str, below: str) -> bool:
        p, q = self.point(obj), self.point(below)
        return bool(np.linalg.norm(p[:2] - q[:2]) < 0.03 and 0.03 < p[2] - q[2] < 0.06)

    def on_peg(self, obj: str) -> bool:
        peg = self.goal("peg")
        p = self.point(obj)
        return bool(
            np.linalg.norm(p[:2] - peg[:2]) < 0.03 and p[2] < self.env.table_offset[2] + 0.05
        )
