"""Shared test fixtures: small real episodes built in memory."""

from __future__ import annotations

import os

import numpy as np
import pytest

from rover.episode import Episode, Event, FrameFacts, GroundTruth, StateType, Subtask

os.environ.setdefault("MUJOCO_GL", "egl")


def make_frames(n: int, size: int = 32, seed: int = 0) -> np.ndarray:
    """n distinct frames: a moving square on a gradient, so every frame hashes differently."""
    ramp = np.linspace(0, 120, size, dtype=np.float32)
    base = np.zeros((size, size, 3), dtype=np.uint8)
    base[..., 0] = ramp[None, :]
    base[..., 1] = ramp[:, None]
    base[..., 2] = (seed * 37) % 200
    frames = np.repeat(base[None], n, axis=0).copy()
    for t in range(n):
        x = int((size - 8) * t / max(n - 1, 1))
        frames[t, 10:18, x : x + 8] = (255, 40 + (t * 7) % 200, 40)
    return frames


@pytest.fixture
def make_episode():
    """Factory: a two-subtask pick-and-place episode with full ground truth."""

    def _make(n: int = 10, size: int = 32, episode_id: str = "ep0") -> Episode:
        half = n // 2
        progress = [t / (n - 1) for t in range(n)]
        facts = []
        for t in range(n):
            holding = "can" if half <= t < n - 1 else None
            facts.append(
                FrameFacts(
                    gripper="closed" if holding else "open",
                    contacts=["can"] if holding else [],
                    holding=holding,
                )
            )
        return Episode(
            id=episode_id,
            task="pick the can and place it in the bin",
            task_group="pick_and_place",
            source="test",
            fps=10,
            frame_indices=list(range(n)),
            view_names=["left"],
            truth=GroundTruth(
                progress=progress,
                state_type=[StateType.expert] * n,
                subtasks=[
                    Subtask(name="grasp the can", start=0, end=half - 1, object="can"),
                    Subtask(name="place the can in the bin", start=half, end=n - 1, object="can"),
                ],
                events=[Event(name="grasp", object="can", frame=half)],
                facts=facts,
                level=3,
            ),
            views={"left": make_frames(n, size)},
        )

    return _make
