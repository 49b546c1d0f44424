"""Can the scripted Panda hold its hand level (pointing forward) at kitchen-fixture heights?

Usage: python benchmarks/forward_reach.py [--steps 150]

The cabinet, microwave and coffee-machine pick-and-place tasks need a hand that points
horizontally into the fixture (`rover.sim.experts.Scripted.pitch = -pi/2`). This drives
robosuite's OSC_POSE controller, as the experts do, toward level-hand targets at the
heights those tasks grasp at (an item on the counter, the microwave cavity, the coffee
drip tray, higher up) from two start poses, and prints how close it gets:

* ``default``: robosuite's Panda start pose (hand down, wrist joint 6 at 2.94 rad);
* ``flipped wrist``: joint 5 turned near its -2.9 rad limit and the hand already level
  at (-0.2, 0, 0.95), found here by damped least squares from a seeded guess.

A row reads: the target, the final position error (cm) and orientation error (deg) after
`--steps` control steps, and the joints that ended within 0.05 rad of a limit.
"""

from __future__ import annotations

import argparse
import os

import numpy as np

TARGETS = {  # name -> world point of the grip site (counter top at z = 0.80)
    "counter item": (-0.10, 0.24, 0.84),
    "microwave cavity": (0.05, -0.13, 0.87),
    "coffee drip tray": (0.06, 0.00, 0.87),
    "counter +10 cm": (-0.10, 0.00, 0.90),
    "counter +25 cm": (-0.10, 0.00, 1.05),
    "counter +45 cm": (-0.10, 0.00, 1.25),
}
PITCH = -np.pi / 2
FLIP_AT = np.array([-0.2, 0.0, 0.95])


def _solve(sim, q: np.ndarray, target: np.ndarray, want: np.ndarray) -> np.ndarray:
    """Damped least-squares IK of the grip site (position and orientation), joint-limited."""
    import mujoco
    from scipy.spatial.transform import Rotation

    m, d = sim.model, sim.data
    robot = sim.env.robots[0]
    qi, vi = np.array(robot._ref_joint_pos_indexes), np.array(robot._ref_joint_vel_indexes)
    lim = m.jnt_range[np.array(robot._ref_joint_indexes)]
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    for _ in range(800):
        d.qpos[qi] = q
        mujoco.mj_forward(m, d)
        err = np.concatenate(
            [
                target - d.site_xpos[sim._eef_site],
                Rotation.from_matrix(want @ d.site_xmat[sim._eef_site].reshape(3, 3).T).as_rotvec(),
            ]
        )
        mujoco.mj_jacSite(m, d, jp, jr, sim._eef_site)
        jac = np.vstack([jp[:, vi], jr[:, vi]])
        step = jac.T @ np.linalg.solve(jac @ jac.T + 1e-2 * np.eye(6), err)
        q = np.clip(q + 0.2 * step, lim[:, 0] + 0.05, lim[:, 1] - 0.05)
    return q


def _start(sim, q: np.ndarray) -> None:
    import mujoco

    robot = sim.env.robots[0]
    sim.reset(0)
    sim.data.qpos[np.array(robot._ref_joint_pos_indexes)] = q
    sim.data.qvel[np.array(robot._ref_joint_vel_indexes)] = 0.0
    mujoco.mj_forward(sim.model, sim.data)
    for part in robot.composite_controller.part_controllers.values():
        if hasattr(part, "update_initial_joints"):  # the OSC's null-space posture
            part.update_initial_joints(q)


def main() -> None:
    os.environ.setdefault("MUJOCO_GL", "egl")
    from rich.console import Console
    from rich.table import Table
    from scipy.spatial.transform import Rotation

    from rover.sim.env import SimEnv
    from rover.sim.experts import Scripted
    from rover.sim.motions import OPEN
    from rover.sim.tasks import get_task

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=150)
    args = ap.parse_args()
    if args.steps < 1:
        ap.error("--steps must be at least 1")
    sim = SimEnv(get_task("kitchen.PickPlaceCounterToSink"))
    sim.reset(0)
    robot = sim.env.robots[0]
    qi = np.array(robot._ref_joint_pos_indexes)
    lim = sim.model.jnt_range[np.array(robot._ref_joint_indexes)]
    down = sim.data.site_xmat[sim._eef_site].reshape(3, 3).copy()
    level = Rotation.from_euler("yz", [PITCH, 0.0]).as_matrix() @ down
    default = sim.data.qpos[qi].copy()
    guess = default.copy()
    guess[4], guess[5], guess[6] = -2.8, 2 * np.pi - (default[1] - default[3]), default[6] - np.pi
    flipped = _solve(sim, _solve(sim, guess, sim.point("eef"), down), FLIP_AT, level)
    poses = {"default": default, "flipped wrist": flipped}

    table = Table(title=f"Level hand (pitch {np.degrees(PITCH):.0f} deg), {args.steps} OSC steps")
    for col in ("start pose", "target", "z", "pos err cm", "rot err deg", "joints at a limit"):
        table.add_column(col)
    for pose, q in poses.items():
        for name, point in TARGETS.items():
            _start(sim, q)
            script = Scripted(sim)
            script.down, script.pitch = down, PITCH
            target = np.array(point)
            for _ in range(args.steps):
                sim.step(script.action(target, OPEN, 0.0, 1.0))
            pos = float(np.linalg.norm(target - sim.point("eef")))
            rot = float(np.linalg.norm(script.rot_error(0.0)))
            q_end = sim.data.qpos[qi]
            stuck = [
                f"j{k + 1} {q_end[k]:.2f}"
                for k in range(len(q_end))
                if min(q_end[k] - lim[k, 0], lim[k, 1] - q_end[k]) < 0.05
            ]
            table.add_row(
                pose,
                name,
                f"{point[2]:.2f}",
                f"{100 * pos:.1f}",
                f"{np.degrees(rot):.0f}",
                ", ".join(stuck) or "-",
            )
    console = Console(width=120)
    console.print(table)
    console.print("flipped-wrist start pose (rad): " + " ".join(f"{v:.3f}" for v in flipped))


if __name__ == "__main__":
    main()
