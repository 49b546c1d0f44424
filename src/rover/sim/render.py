"""Render saved simulator states to video frames, only the frames a video needs.

Simulation runs without cameras; afterwards the generator picks the N states of the
video and renders each view here with one `mujoco.Renderer` on the task's model and a
private `MjData` (so rendering never disturbs the simulation). Views:

- ``wrist``: robosuite's eye-in-hand camera on the Panda hand.
- ``left`` / ``right``: free cameras beside the robot, on its left and on its right,
  looking past the arm at the task (no model edit needed, so robosuite/RoboCasa models
  load as is). The generator aims them at the task's centre (`view_centre`: gripper,
  objects and goals at the start), so every task's objects and gripper are in frame,
  and each view swings round or rises (`aim_views`) until nothing but the robot stands
  between it and the gripper or the task's centre at the video's start and end (from
  the robot's right, robosuite's Door panel hides the handle and the hand).
- any camera name in the model (``frontview``, ``agentview``, ...) also works.

Cost is geometry-bound on a CPU rasteriser, so multisampling is off, the offscreen buffer
is sized to the frame, and shadows and reflections are off. `mujoco.Renderer` already
returns images upright (row 0 is the top of the picture).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco  # noqa: E402

from rover.errors import InputError  # noqa: E402

WRIST_CAMERA = "robot0_eye_in_hand"


@dataclass(frozen=True)
class FreeView:
    """A free camera: look at `lookat` from `distance` m, azimuth/elevation in degrees."""

    lookat: tuple[float, float, float]
    distance: float
    azimuth: float
    elevation: float


# Workspace views for robosuite's table tasks (table top centre ~ (0, 0, 0.8); the robot
# base stands at x ~ -0.56 looking along +x). A free camera sits at
# lookat - distance * (cos el cos az, cos el sin az, sin el): azimuth -60 puts it behind
# and to the left of the task (the robot's left, +y), +60 to its right.
FREE_VIEWS: dict[str, FreeView] = {
    "left": FreeView(lookat=(0.0, 0.0, 0.9), distance=1.45, azimuth=-60.0, elevation=-30.0),
    "right": FreeView(lookat=(0.0, 0.0, 0.9), distance=1.45, azimuth=60.0, elevation=-30.0),
}
VIEW_NAMES = ["wrist", "left", "right"]
GRIP_SITE = "gripper0_right_grip_site"  # robosuite's Panda grip point (between the fingers)
# (azimuth, elevation) tried for each free view, its default first: swung toward the side
# of the table, then toward the front, then raised (the first one that sees the gripper
# and the task's centre unhidden is used)
AIM_CANDIDATES: dict[str, list[tuple[float, float]]] = {
    name: [
        (sign * az, el)
        for az, el in ((60, -30), (75, -30), (45, -30), (90, -35), (30, -35), (60, -50), (90, -55))
    ]
    for name, sign in (("left", -1.0), ("right", 1.0))
}
SEEN_SLACK = 0.06  # m: a hit this close before a point is the point's own surface


def check_views(views: list[str]) -> None:
    """Raise a one-line InputError naming the valid views for an unknown one."""
    for v in views:
        if v not in VIEW_NAMES:
            raise InputError(f"unknown view {v!r}; valid views: {', '.join(VIEW_NAMES)}")


class StateRenderer:
    """Renders flat robosuite states of one model from named views at one size."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int | None = None) -> None:
        height = height or width
        self.model = model
        model.vis.quality.offsamples = 0
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
        self.data = mujoco.MjData(model)
        self.renderer = mujoco.Renderer(model, height=height, width=width)
        self.width, self.height = width, height
        # robosuite puts collision geoms in group 0 and visual meshes in group 1: hide 0
        self.option = mujoco.MjvOption()
        self.option.geomgroup[0] = 0

    def camera(
        self, view: str, lookat: np.ndarray | None = None, aim: FreeView | None = None
    ) -> mujoco.MjvCamera | int:
        """The camera of a view; ``aim`` (from `aim_views`) replaces a free view's
        default distance, azimuth and elevation."""
        if view == "wrist":
            view = WRIST_CAMERA
        # a model may carry its own camera for a view (the kitchen's, jittered per scene)
        own = int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, f"rover_{view}"))
        if own >= 0:
            return own
        if view in FREE_VIEWS:
            fv = aim or FREE_VIEWS[view]
            cam = mujoco.MjvCamera()
            cam.type = mujoco.mjtCamera.mjCAMERA_FREE
            cam.lookat[:] = fv.lookat if lookat is None else lookat
            cam.distance, cam.azimuth, cam.elevation = fv.distance, fv.azimuth, fv.elevation
            return cam
        cid = int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, view))
        if cid < 0:
            raise InputError(f"unknown view {view!r}; valid views: {', '.join(VIEW_NAMES)}")
        return cid

    def set_state(self, state: np.ndarray) -> None:
        """Pose the private MjData from a flat ``[time, qpos, qvel]`` state."""
        m, d = self.model, self.data
        d.time = state[0]
        d.qpos[:] = state[1 : 1 + m.nq]
        d.qvel[:] = state[1 + m.nq : 1 + m.nq + m.nv]
        mujoco.mj_kinematics(m, d)
        mujoco.mj_camlight(m, d)

    def render(
        self, states: np.ndarray, views: list[str], lookat: np.ndarray | None = None
    ) -> dict[str, np.ndarray]:
        """Frames (T, H, W, 3) uint8 per view for each state in order; free views look at
        `lookat` (default: the table centre), from where `aim_views` sees the gripper and
        `lookat` unhidden in the first and last state."""
        check_views(views)
        aims: dict[str, FreeView] = {}
        if lookat is not None and len(states):
            aims = self.aim_views(np.asarray(states)[[0, -1]], lookat)
        cams = {v: self.camera(v, lookat, aims.get(v)) for v in views}
        out = {v: np.empty((len(states), self.height, self.width, 3), np.uint8) for v in views}
        for t, state in enumerate(states):
            self.set_state(np.asarray(state, dtype=np.float64))
            for v, cam in cams.items():
                self.renderer.update_scene(self.data, camera=cam, scene_option=self.option)
                scn = self.renderer.scene
                scn.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
                scn.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
                out[v][t] = self.renderer.render()
        return out

    def aim_views(
        self, states: np.ndarray, lookat: np.ndarray, points: list[np.ndarray] | None = None
    ) -> dict[str, FreeView]:
        """For each free view, the first of its `AIM_CANDIDATES` from which the gripper,
        `lookat` and any extra world ``points`` are in frame and hidden by nothing but the
        robot in every given state; the candidate that sees most of them when none sees
        all (a free view the model defines itself is left alone)."""
        grip = int(mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, GRIP_SITE))
        out: dict[str, FreeView] = {}
        for view, base in FREE_VIEWS.items():
            own = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, f"rover_{view}")
            if own >= 0:
                continue
            best, best_seen = None, -1
            for az, el in AIM_CANDIDATES[view]:
                fv = FreeView(tuple(float(x) for x in lookat), base.distance, az, el)
                seen = 0
                for state in states:
                    self.set_state(np.asarray(state, dtype=np.float64))
                    targets = [np.asarray(lookat, dtype=np.float64), *(points or [])]
                    if grip >= 0:
                        targets.append(self.data.site_xpos[grip].copy())
                    seen += sum(self._seen(fv, p) for p in targets)
                if seen > best_seen:
                    best, best_seen = fv, seen
                if seen == len(states) * len(targets):
                    break
            if best is not None:
                out[view] = best
        return out

    def _seen(self, fv: FreeView, point: np.ndarray) -> bool:
        """In frame of `fv` and not hidden by any geom but the robot's (posed data)."""
        if not _in_frame(fv, point):
            return False
        cam = camera_position(fv)
        ray = point - cam
        length = float(np.linalg.norm(ray))
        unit = ray / length
        gid = np.array([-1], dtype=np.int32)
        travelled = 0.0
        for _ in range(32):  # step through the robot's own geoms
            start = cam + unit * travelled
            dist = mujoco.mj_ray(self.model, self.data, start, unit, None, 1, -1, gid)
            if dist < 0 or travelled + dist >= length - SEEN_SLACK:
                return True
            body = mujoco.mj_id2name(
                self.model, mujoco.mjtObj.mjOBJ_BODY, int(self.model.geom_bodyid[gid[0]])
            )
            if not (body or "").startswith(("robot0_", "gripper0_", "mount0_")):
                return False
            travelled += dist + 1e-3
        return True

    def close(self) -> None:
        self.renderer.close()


def camera_position(fv: FreeView) -> np.ndarray:
    """Where MuJoCo puts a free camera: lookat - distance * forward."""
    return np.asarray(fv.lookat, dtype=np.float64) - fv.distance * _forward(fv)


def _forward(fv: FreeView) -> np.ndarray:
    az, el = np.radians(fv.azimuth), np.radians(fv.elevation)
    return np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])


def _in_frame(fv: FreeView, point: np.ndarray, fovy: float = 45.0) -> bool:
    fwd = _forward(fv)
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    v = np.asarray(point, dtype=np.float64) - camera_position(fv)
    depth = float(v @ fwd)
    if depth <= 0:
        return False
    half = np.tan(np.radians(fovy) / 2)
    return abs(v @ right) / depth < half and abs(v @ up) / depth < half


def in_view(
    view: str,
    lookat: np.ndarray,
    point: np.ndarray,
    fovy: float = 45.0,
    aim: FreeView | None = None,
) -> bool:
    """Whether a world point falls inside a square frame of free view `view` aimed at
    `lookat` (pinhole projection with MuJoCo's free-camera geometry and vertical fovy);
    ``aim`` (from `StateRenderer.aim_views`) replaces the view's default placement."""
    base = aim or FREE_VIEWS[view]
    fv = FreeView(tuple(float(x) for x in lookat), base.distance, base.azimuth, base.elevation)
    return _in_frame(fv, point, fovy)


def view_centre(sim) -> np.ndarray:
    """Where the free views look for a task: the middle of the gripper, the task objects
    and their goals in the simulator's current state (an episode's first state)."""
    pts = [sim.point("eef")] + [sim.point(o.name) for o in sim.spec.objects]
    for s in sim.spec.subtasks:
        if s.goal is not None:
            pts.append(sim.point(s.goal))
    lo, hi = np.min(pts, axis=0), np.max(pts, axis=0)
    centre = (lo + hi) / 2
    centre[2] = min(max(centre[2], 0.85), 1.0)  # about the table top, never the ceiling
    return centre
