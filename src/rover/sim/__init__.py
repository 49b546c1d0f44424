"""Benchmark generator: robosuite tasks, scripted experts, perturbed trajectories, truth.

Importing this package is cheap and needs no MuJoCo; the simulator parts import it
lazily. `MUJOCO_GL` defaults to EGL here, before anything imports mujoco, because the
renderer backend is fixed at mujoco's first import (set it to ``osmesa`` yourself when
EGL is unavailable).
"""

from __future__ import annotations

import os
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")


def bundled_dataset_path() -> Path:
    """The small dataset shipped with rover (two tasks, few episodes, 30 frames, 128 px).

    Tests and the offline demo read it without MuJoCo; `docs/generate.md` gives the
    exact `rover generate` command that re-creates it.
    """
    return Path(__file__).resolve().parent.parent / "data" / "bundled"
