"""Fixtures for the simulation tests: one SimEnv per task per test session (envs are slow
to build), shared by every sim test file."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="session")
def sim_env():
    """Factory: the cached `SimEnv` of a task (robosuite must be installed)."""
    pytest.importorskip("robosuite")
    from rover.sim.env import SimEnv
    from rover.sim.tasks import get_task

    cache: dict = {}

    def _get(task: str):
        if task not in cache:
            cache[task] = SimEnv(get_task(task))
        return cache[task]

    return _get


class ActionRecorder:
    """A stand-in simulator for plan tests: records the actions a plan sends (no physics)."""

    def __init__(self, dims: int) -> None:
        self.action_low = -np.ones(dims)
        self.action_high = np.ones(dims)
        self.s = np.zeros(3)
        self.actions: list[np.ndarray] = []

    def get_state(self):
        return self.s.copy()

    def set_state(self, s):
        self.s = np.asarray(s, dtype=float).copy()

    def step(self, a):
        self.actions.append(np.asarray(a).copy())


@pytest.fixture
def action_recorder():
    """``action_recorder(dims)``: a fresh `ActionRecorder` with that many action channels."""
    return ActionRecorder
