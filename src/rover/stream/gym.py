"""`ProgressReward`: ROVER's live progress as a Gymnasium wrapper (dense reward, success).

    env = ProgressReward(env, "open the drawer", vlm, every=10)
    obs, info = env.reset()
    obs, reward, terminated, truncated, info = env.step(action)
    info["progress"], info["progress_delta"]

On reset and then every `every` steps the wrapper takes a frame (`frame(env)`, default
`env.render()`, which must give an (H, W, 3) uint8 RGB array), pushes it to a
`RoverStream` and puts into `info`: `progress` (0..100 over the task, as stitched so
far), `progress_delta` (its change since the previous pushed frame), `progress_subtask`
(the subtask path), `progress_complete`, `progress_calls` and `progress_updated` (whether
this step pushed a frame). Between pushes the last values are repeated with a delta of
0. With `reward_scale` != 0 the reward gets `reward_scale * progress_delta / 100` added
(so a whole task is worth `reward_scale`). `trace()` gives the episode's trace (on reset
the previous episode's trace is kept in `last_trace`).

The wrapper runs its own event loop for the stream's calls, so it works from ordinary
synchronous RL code; `observe(position)`, when given, is called just before each frame is
pushed (a live truth source such as `LiveSimOracle.observe`).
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

import numpy as np

from rover.errors import InputError, MissingExtraError
from rover.methods.trace import Trace
from rover.stream.rover_stream import FrameEstimate, RoverStream
from rover.vlm.types import VLM

try:
    import gymnasium
except ImportError as exc:  # pragma: no cover - depends on the install
    raise MissingExtraError("gymnasium", "sim", "the ProgressReward wrapper") from exc


class ProgressReward(gymnasium.Wrapper):
    """Adds ROVER's progress to `info` (and optionally the reward) every `every` steps."""

    def __init__(
        self,
        env: gymnasium.Env,
        task: str,
        vlm: VLM,
        *,
        every: int = 1,
        reward_scale: float = 0.0,
        frame: Callable[[gymnasium.Env], np.ndarray] | None = None,
        observe: Callable[[int], None] | None = None,
        **params: Any,
    ) -> None:
        super().__init__(env)
        if every < 1:
            raise InputError(f"every must be at least 1 step, got {every}")
        self.task, self.vlm, self.every = task, vlm, int(every)
        self.reward_scale = float(reward_scale)
        self._frame = frame or (lambda e: e.render())
        self._observe = observe
        self._params = params
        self._loop = asyncio.new_event_loop()
        self._stream: RoverStream | None = None
        self._steps = 0
        self._last: FrameEstimate | None = None
        self.last_trace: Trace | None = None

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        self._end_episode()
        self._stream = RoverStream(self.task, self.vlm, **self._params)
        self._steps, self._last = 0, None
        return obs, {**info, **self._push()}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        if self._stream is None:
            raise InputError("call reset() before step()")
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._steps += 1
        if self._steps % self.every == 0:
            extra = self._push()
            reward = float(reward) + self.reward_scale * extra["progress_delta"] / 100.0
        else:
            extra = self._info(self._last, delta=0.0, updated=False)
        return obs, reward, terminated, truncated, {**info, **extra}

    def trace(self) -> Trace:
        """The current episode's trace so far (ends the stream; the next step needs reset)."""
        if self._stream is None:
            raise InputError("no episode: call reset() first")
        trace = self._loop.run_until_complete(self._stream.trace())
        self._stream = None
        self.last_trace = trace
        return trace

    def close(self) -> None:
        try:
            self._end_episode()
            close = getattr(self.vlm, "aclose", None)
            if close is not None and not self._loop.is_closed():
                self._loop.run_until_complete(close())
        finally:
            if not self._loop.is_closed():
                self._loop.close()
            super().close()

    # -- internals -------------------------------------------------------------------------

    def _end_episode(self) -> None:
        if self._stream is not None and self._stream.frames_pushed:
            self.trace()
        self._stream = None

    def _push(self) -> dict[str, Any]:
        assert self._stream is not None
        position = self._stream.frames_pushed
        if self._observe is not None:
            self._observe(position)
        frame = np.asarray(self._frame(self.env))
        est = self._loop.run_until_complete(self._stream.push(frame, index=self._steps))
        before = 0.0 if self._last is None else self._last.progress
        self._last = est
        return self._info(est, delta=est.progress - before, updated=True)

    @staticmethod
    def _info(est: FrameEstimate | None, delta: float, updated: bool) -> dict[str, Any]:
        return {
            "progress": 0.0 if est is None else est.progress,
            "progress_delta": float(delta),
            "progress_subtask": [] if est is None else list(est.subtask_path),
            "progress_complete": False if est is None else est.complete,
            "progress_calls": 0 if est is None or not updated else est.calls,
            "progress_updated": updated,
        }
