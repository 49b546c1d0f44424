"""Live progress: ROVER on frames as they arrive (a camera, a running policy, a folder).

- `RoverStream(task, vlm, **params)`: `await push(frame) -> FrameEstimate`, then
  `await trace()`; the same code as `rover reason`, so a video pushed frame by frame
  gives that video's trace.
- `ProgressReward`: a Gymnasium wrapper adding progress (and its change) to `info`, and
  optionally to the reward, every k steps (needs `gymnasium`, extra `sim`).
- `LiveSimOracle`: the oracle for a running rover simulation, answering from a ground
  truth built frame by frame from the simulator's facts.
- `rover watch DIR --task ...` (rover.commands.watch) follows a folder of frames.
"""

from __future__ import annotations

from typing import Any

from rover.stream.rover_stream import FrameEstimate, RoverStream

__all__ = ["FrameEstimate", "LiveSimOracle", "ProgressReward", "RoverStream"]


def __getattr__(name: str) -> Any:
    # gymnasium and the simulator are optional: imported only when asked for
    if name == "ProgressReward":
        from rover.stream.gym import ProgressReward

        return ProgressReward
    if name == "LiveSimOracle":
        from rover.stream.live_truth import LiveSimOracle

        return LiveSimOracle
    raise AttributeError(name)
