"""Ground truth for a simulation that is still running, and the oracle that reads it.

The offline oracle (`rover.vlm.oracle`) answers from a finished episode's truth: the
value function compares the whole trajectory with the expert's, and a subtask's progress
is scaled by where that subtask *ends*. Neither exists while the policy runs. The live
truth is built frame by frame from what the simulator knows now:

- facts: `rover.sim.facts.frame_facts` of the current state (descriptions, as offline);
- the current subtask: the first of the task's subtasks whose end signal
  (`SimEnv.predicate`, e.g. "grasped:cube") has not yet held, taken in order;
- its progress: the goal-focused distance y of that subtask (the value function's first
  term, `rover.sim.value.goal_distance`) relative to its value when the subtask began,
  ``100 (y0 - y) / y0`` held below 100 until the end signal holds;
- full-task progress: ``(k + p_k / 100) / n`` over the n subtasks (k of them done).

These fill a growing `GroundTruth` (subtask spans so far, the current one ending at the
latest frame) that the ordinary `BoundOracle` answers from, so every reply format stays
the oracle's own. It is a cruder truth than the offline value function (no expert
keypoints, no regressions measured against the expert): good for wiring, demos and
upper-bound checks of a live loop, labelled as oracle output like every oracle answer.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rover.episode import Episode, GroundTruth, Subtask
from rover.errors import BackendError
from rover.vlm.base import RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.oracle import BoundOracle, OracleBackend
from rover.vlm.types import Prompt, SamplingParams

if TYPE_CHECKING:
    from rover.sim.env import SimEnv
    from rover.sim.tasks.base import SubtaskSpec


class LiveSimOracle(BoundOracle):
    """The oracle for a live rover simulation; call `observe(position)` once per frame.

    `observe(0)` starts a new episode (after each reset); each later call adds the
    simulator's current state as the next frame, before that frame is pushed.
    """

    def __init__(self, sim: SimEnv, config: BackendConfig | None = None) -> None:
        OracleBackend.__init__(self, config)  # BoundOracle's own init waits for a frame
        self.sim = sim
        self._config = config
        self.episode = None  # type: ignore[assignment]  # none until the first observe
        self.subtask_starts: list[int] = []  # position where each begun subtask began
        self.subtask_ends: list[int] = []  # position where each finished subtask ended
        self._y0 = 0.0
        self._held: str | None = None

    def bind(self, episode: Episode) -> LiveSimOracle:
        return self  # the truth is the running simulation, not a recorded episode

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        if self.episode is None:
            raise BackendError("LiveSimOracle: observe(0) must come before the first call")
        return await super()._generate(prompt, params)

    # -- live truth ------------------------------------------------------------------------

    def observe(self, position: int) -> None:
        """Record the simulator's current state as frame `position` (0: a new episode)."""
        from rover.sim.facts import frame_facts

        n_seen = 0 if self.episode is None else self.episode.num_frames
        if position not in (0, n_seen):
            raise BackendError(f"LiveSimOracle: frame {position} observed after {n_seen}")
        spec = self.sim.spec
        facts = frame_facts(self.sim, None, None if position == 0 else self._held)
        self._held = facts.holding
        if position == 0:
            self.subtask_starts, self.subtask_ends = [0], []
            self._y0 = self._distance(spec.subtasks[0])
        subs = spec.subtasks
        k = len(self.subtask_ends)
        while k < len(subs) and self.sim.predicate(subs[k].end_signal):
            self.subtask_ends.append(position)
            k += 1
            if k < len(subs):
                self.subtask_starts.append(position)
                self._y0 = self._distance(subs[k])
        if k >= len(subs):
            value = 1.0
        else:
            y = self._distance(subs[k])
            p = 0.0 if self._y0 <= 1e-9 else float(np.clip((self._y0 - y) / self._y0, 0.0, 0.99))
            value = (k + p) / len(subs)
        if position == 0:
            self._start_episode(value, facts)
        else:
            ep = self.episode
            assert ep is not None and ep.truth is not None and ep.truth.facts is not None
            ep.frame_indices.append(position)
            ep.truth.progress.append(value)
            ep.truth.facts.append(facts)
        self._spans(position)

    def _start_episode(self, value: float, facts) -> None:
        spec = self.sim.spec
        truth = GroundTruth(progress=[value], facts=[facts], progress_source="simulation")
        episode = Episode(
            id=f"live-{spec.name}",
            task=spec.description,
            source=f"sim:{spec.name}",
            frame_indices=[0],
            view_names=["live"],
            truth=truth,
            extra={"sim_task": spec.name},
        )
        BoundOracle.__init__(self, episode, self._config)

    def _spans(self, last: int) -> None:
        """Subtask spans so far: finished ones, then the current one up to `last`."""
        assert self.episode is not None and self.episode.truth is not None
        subs = self.sim.spec.subtasks
        spans = []
        for j, start in enumerate(self.subtask_starts):
            end = self.subtask_ends[j] if j < len(self.subtask_ends) else last
            spans.append(Subtask(name=subs[j].name, start=start, end=end, object=subs[j].object))
        self.episode.truth.subtasks = spans

    def _distance(self, sub: SubtaskSpec) -> float:
        from rover.sim.value import goal_distance

        point = self.sim.point
        robot = np.stack([point(n) for n in sub.robot_points])[None]
        contacts = np.stack([point(n) for n in sub.object_points])[None]
        goal = point(sub.goal)[None] if sub.goal else None
        obj = point(sub.object)[None]
        return float(goal_distance(robot, contacts, obj, goal, sub.beta)[0])
