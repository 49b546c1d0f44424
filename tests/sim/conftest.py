"""Fixtures for the simulation tests: one SimEnv per task per test session (envs are slow
to build), shared by every sim test file."""

from __future__ import annotations

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
