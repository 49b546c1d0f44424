"""Can the scripted Panda hold its hand level (pointing forward) where the forward grasp works?

Usage: python benchmarks/forward_reach.py [--steps 150] [--seed 0]

The microwave, cabinet and coffee-machine pick-and-place tasks take their
item with a hand that points horizontally into the fixture
(`rover.sim.experts.Scripted.pitch = -pi/2`). This drives robosuite's OSC_POSE
controller, as the experts do, toward level-hand targets in the scene of
kitchen.PickPlaceCounterToMicrowave (seed `--seed`: the item's counter spot, the
microwave's mouth and cavity, higher over the counter) from two start poses, and prints
how close it gets:

* ``default``: robosuite's Panda start pose (hand down, wrist joint 6 at 2.94 rad);
* ``ready``: the forward grasp's level-hand start (`rover.sim.kitchen.forward_grasp.READY_Q`,
  hand at (-0.25, 0.05, 0.92)), which the forward-grasp tasks start in.

Each target is driven to from a fresh reset, with the item moved out of the way. A row
reads: the target, the final position error (cm) and orientation error (deg) after
`--steps` control steps, and the joints that ended within 0.05 rad of a limit.
"""

from __future__ import annotations

import argparse
import os

import numpy as np

PITCH = -np.pi / 2


def _start(sim, q: np.ndarray, seed: int) -> None:
    """The scene of `seed`, the item set aside, the arm at `q` with the OSC posture there."""
    import mujoco

    robot = sim.env.robots[0]
    sim.reset(seed)
    a, _ = sim.env.item_qpos_addr
    sim.data.qpos[a : a + 3] = [-0.3, -0.9, 0.9]  # off the counter's working stretch
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

    from rover.sim.env import SimEnv
    from rover.sim.experts import Scripted
    from rover.sim.kitchen.forward_grasp import HAND_DOWN, READY_Q
    from rover.sim.motions import OPEN
    from rover.sim.tasks import get_task

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--steps", type=int, default=150)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    if args.steps < 1:
        ap.error("--steps must be at least 1")
    sim = SimEnv(get_task("kitchen.PickPlaceCounterToMicrowave"))
    sim.reset(args.seed)
    env = sim.env
    robot = env.robots[0]
    qi = np.array(robot._ref_joint_pos_indexes)
    lim = sim.model.jnt_range[np.array(robot._ref_joint_indexes)]
    down = np.array(HAND_DOWN)
    place = env.scene.layout["Microwave"]
    ahead = np.array([np.cos(place.yaw), np.sin(place.yaw), 0.0])
    cavity = sim.data.site_xpos[sim.model.site("Microwave_interior").id].copy()
    cavity[2] = 0.80 + 0.01 + 0.045
    spot = sim.point(sim.spec.objects[0].name)
    targets = {
        "counter spot": spot,
        "microwave mouth": cavity - 0.2 * ahead,
        "microwave cavity": cavity,
        "counter +25 cm": np.array([-0.10, 0.0, 1.05]),
        "counter +45 cm": np.array([-0.10, 0.0, 1.25]),
    }
    poses = {"default": np.array(robot.robot_model.init_qpos), "ready": np.array(READY_Q)}
    yaw = float(place.yaw)  # the expert points the hand along the microwave's depth

    table = Table(title=f"Level hand (pitch {np.degrees(PITCH):.0f} deg), {args.steps} OSC steps")
    for col in ("start pose", "target", "z", "pos err cm", "rot err deg", "joints at a limit"):
        table.add_column(col)
    for pose, q in poses.items():
        for name, point in targets.items():
            _start(sim, q, args.seed)
            script = Scripted(sim)
            script.down, script.pitch = down, PITCH
            target = np.asarray(point, dtype=np.float64)
            for _ in range(args.steps):
                sim.step(script.action(target, OPEN, yaw, 1.0))
            pos = float(np.linalg.norm(target - sim.point("eef")))
            rot = float(np.linalg.norm(script.rot_error(yaw)))
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
    console.print("ready start pose (rad): " + " ".join(f"{v:.3f}" for v in READY_Q))


if __name__ == "__main__":
    main()
