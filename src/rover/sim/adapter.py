"""The narrow interface between simulation back ends and trajectory/value code.

Trajectory generation (`rover.sim.perturb`) and ground-truth values (`rover.sim.value`)
only need to save, restore and step a simulator and read a few named points. Keeping that
surface in one Protocol lets the robosuite wrapper (`rover.sim.env`) implement it while the
trajectory code stays testable with a pure-numpy fake simulator.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class SimAdapter(Protocol):
    """What perturbation and value code may ask of a simulator.

    States are flat arrays in robosuite's layout ``[time, qpos..., qvel...]``
    (``sim.get_state().flatten()``); they are the only thing kept per control step, so a
    trajectory can be re-rendered or re-measured later by setting them again.

    Attributes:
        action_low: (A,) lower bounds of the action space; random deviations draw
            actions uniformly between ``action_low`` and ``action_high``.
        action_high: (A,) upper bounds of the action space.
    """

    action_low: np.ndarray
    action_high: np.ndarray

    def get_state(self) -> np.ndarray:
        """Return the current flat simulator state."""
        ...

    def set_state(self, state: np.ndarray) -> None:
        """Restore a flat state and recompute derived quantities (``mj_forward``)."""
        ...

    def step(self, action: np.ndarray) -> None:
        """Advance one control step with ``action`` (no rendering)."""
        ...

    def interpolate(self, a: np.ndarray, b: np.ndarray, alpha: float) -> np.ndarray:
        """State a fraction ``alpha`` of the way from ``a`` to ``b``.

        Positions and hinge/slide joints interpolate linearly, free-joint and ball-joint
        orientations by quaternion slerp (see `rover.sim.interp.interpolate_state`).
        """
        ...

    def entity_positions(self) -> np.ndarray:
        """(B, 3) world positions: robot end effector first, then every task object."""
        ...

    def point(self, name: str) -> np.ndarray:
        """(3,) world position of a named point in the current state.

        Names: ``"eef"``, ``"left_finger"``, ``"right_finger"``, ``"<object>"`` (object
        centre), ``"<object>:<site>"`` (an object contact point or handle), ``"goal:<name>"``.
        """
        ...

    def success(self) -> bool:
        """Whether the whole task is solved in the current state."""
        ...
