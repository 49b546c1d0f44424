"""Trajectory levels: how much of the task a generated video gets done (paper App. B, Table 5).

Table 5 orders videos of a task by the amount of the task completed: "fail to approach",
"approach", "contact", "pick up", ..., up to full completion with near-expert behaviour.
A `LevelSpec` turns one row into knobs for `rover.sim.perturb.plan_trajectory`: where the
trajectory stops following the expert for good (a subtask and a fraction of it), how many
recovered deviations it suffers before that, and how wild they are. Every range is sampled
per video, so videos of one level differ in deviation times, counts, magnitudes, recovery
points and recovery smoothness (Sec. 4.1, "we ensure diversity ...").
"""

from __future__ import annotations

import zlib
from collections.abc import Mapping, Sequence
from typing import Literal

import numpy as np
from pydantic import BaseModel, Field, model_validator

IntRange = tuple[int, int]
FloatRange = tuple[float, float]
Grip = Literal["random", "keep", "open", "close"]


class LevelSpec(BaseModel):
    """One trajectory level of a task (one row of App. B, Table 5).

    Ranges are inclusive ``(low, high)`` and sampled uniformly per video.

    Attributes:
        level: 1 = least of the task done; the highest level completes the task.
        name: what the level shows, e.g. "Approach the can" (documentation and reports).
        terminate_subtask: subtask index in which the video ends in a final, unrecovered
            random deviation; None means the video follows the expert to the task's end.
        terminate_at: fraction of that subtask's expert steps completed before the final
            deviation starts (0 = at its first step, 1 = at its last step).
        terminal_w: length (control steps) of the final, unrecovered deviation.
        deviations: number of recovered deviations before the end.
        w: length of each recovered deviation in control steps.
        scale: magnitude of random actions as a fraction of the action range around its
            centre (1.0 = uniform over the whole action space, as in the paper).
        hold: a new random action is drawn every `hold` steps (1 = paper; larger values
            give visibly larger excursions because per-step noise averages out).
        h: recovery horizon: the recovery heads for expert state ``q + h``.
        n_interp: interpolation steps of a recovery (smoothness).
        nested_prob: probability that a recovery is interrupted by a nested deviation.
        milestone_cut: where the video leaves the expert, as a fraction of the stretch of
            the expert's own demo between achieving this level's last component and
            achieving its next one (`rover.sim.cuts`); None, or a demo in which the
            expert never shows those components, falls back to ``terminate_subtask``
            and ``terminate_at``.
        terminal_grip: the gripper channel during the final deviation: "random" (the
            paper: uniform like every other channel), "keep" (the expert's command at
            the cut), "open" or "close" (forced, e.g. to let go of what was picked up,
            or to keep holding what is carried).
        terminal_drift: added to the final deviation's x, y, z action channels (then
            clipped): (0, 0, -0.5) sets a just-lifted object back down as the fingers
            open instead of dropping it; (0, 0, 0.3) backs the open hand off upwards.
        terminal_settle: steps before the final deviation's random ones that keep the
            gripper closed and move the hand by ``terminal_drift`` alone, which then
            stops (0: none, the paper): a just-lifted object is lowered back to the
            table in the grasp and only then let go, so the open hand stays at it (the
            hand cannot come back down as fast as a released object falls).
    """

    level: int = Field(ge=1)
    name: str = ""
    terminate_subtask: int | None = None
    terminate_at: FloatRange = (0.0, 0.0)
    terminal_w: IntRange = (20, 60)
    deviations: IntRange = (0, 0)
    w: IntRange = (5, 20)
    scale: FloatRange = (0.5, 1.0)
    hold: IntRange = (1, 6)
    h: IntRange = (5, 25)
    n_interp: IntRange = (5, 15)
    nested_prob: float = Field(default=0.0, ge=0.0, le=1.0)
    milestone_cut: FloatRange | None = None
    terminal_grip: Grip = "random"
    terminal_drift: tuple[float, float, float] = (0.0, 0.0, 0.0)
    terminal_settle: IntRange = (0, 0)

    @model_validator(mode="after")
    def _ranges_ordered(self) -> LevelSpec:
        for field in (
            "terminate_at",
            "terminal_w",
            "deviations",
            "w",
            "scale",
            "hold",
            "terminal_settle",
        ):
            lo, hi = getattr(self, field)
            if lo > hi or lo < 0:
                raise ValueError(f"level {self.level}: {field} must be 0 <= low <= high")
        for field in ("h", "n_interp"):
            lo, hi = getattr(self, field)
            if lo < 1 or lo > hi:
                raise ValueError(f"level {self.level}: {field} must be 1 <= low <= high")
        if self.terminate_at[1] > 1.0:
            raise ValueError(f"level {self.level}: terminate_at must lie in [0, 1]")
        if self.milestone_cut is not None:
            lo, hi = self.milestone_cut
            if not 0.0 <= lo <= hi <= 1.0:
                raise ValueError(f"level {self.level}: milestone_cut must be 0 <= low <= high <= 1")
        if self.w[0] < 1 or self.terminal_w[0] < 1 or self.hold[0] < 1:
            raise ValueError(f"level {self.level}: w, terminal_w and hold must be >= 1")
        return self

    @property
    def completes(self) -> bool:
        """Whether videos of this level follow the expert to the end of the task."""
        return self.terminate_subtask is None


def default_levels(milestones: Sequence[Sequence[str]]) -> list[LevelSpec]:
    """Table-5-style levels from the milestones of each subtask.

    Each subtask lists the milestones reached while doing it (e.g. grasp:
    ["Approach the can", "Contact the can"]). Level 1 fails early in the first subtask;
    each further level stops after one more milestone; the last level completes the task
    with small recovered deviations (near-expert). A subtask with k milestones is cut at
    fractions 1/(k+1), 2/(k+1), ... of its expert steps.

    Args:
        milestones: per subtask, the names of the milestones inside it, in order. The
            final milestone of a subtask is its completion and need not be listed.

    Returns:
        Levels 1..L, L = 1 + sum(len(m) + 1 for m in milestones).
    """
    levels: list[LevelSpec] = [
        LevelSpec(
            level=1,
            name="Fail to make progress",
            terminate_subtask=0,
            terminate_at=(0.0, 0.1),
            terminal_w=(40, 80),
            scale=(0.7, 1.0),
        )
    ]
    for i, names in enumerate(milestones):
        k = len(names)
        cuts = [(m + 1) / (k + 1) for m in range(k)] + [None]
        for m, cut in enumerate(cuts):
            label = names[m] if m < k else f"Complete subtask {i + 1}"
            last_subtask = i == len(milestones) - 1
            if cut is None and last_subtask:
                levels.append(
                    LevelSpec(
                        level=len(levels) + 1,
                        name="Complete the task",
                        deviations=(0, 2),
                        w=(3, 10),
                        scale=(0.2, 0.6),
                        h=(3, 12),
                        n_interp=(4, 10),
                        nested_prob=0.2,
                    )
                )
                continue
            if cut is None:  # stop right at the start of the next subtask
                sub, at = i + 1, (0.0, 0.05)
            else:
                sub, at = i, (max(cut - 0.1, 0.0), min(cut + 0.1, 1.0))
            levels.append(
                LevelSpec(
                    level=len(levels) + 1,
                    name=label,
                    terminate_subtask=sub,
                    terminate_at=at,
                    terminal_w=(15, 40),  # short enough that the end still shows the level
                    deviations=(0, 2),
                    nested_prob=0.3,
                )
            )
    return levels


# How a level that stops before component ``<kind>:<object>`` ends, by that kind: where in
# the stretch between the expert achieving the level's last component and achieving that
# one the video leaves the expert (`rover.sim.cuts.cut_window` says what the stretch is),
# what the gripper does in the final deviation, and how long and wild that deviation is.
# The paper's ending is uniform over every channel; these endings are bounded so that the
# deviation neither completes the next component nor undoes the achieved ones.
_PRE_GRASP = {"milestone_cut": (0.4, 0.9), "terminal_grip": "open", "terminal_w": (15, 35),
              "scale": (0.4, 0.8)}  # fmt: skip
ENDINGS_BY_KIND: dict[str, dict] = {
    # fail to approach: leave early, anything goes (as the paper)
    "approach": {"milestone_cut": (0.0, 0.2), "terminal_grip": "random"},
    # approached, not touched: fingers open, back off upwards a little (a few cm), so
    # the video ends clearly short of a contact video's open hand resting at the part
    "contact": {
        "milestone_cut": (0.1, 0.5),
        "terminal_grip": "open",
        "terminal_w": (10, 20),
        "scale": (0.1, 0.3),
        "terminal_drift": (0.0, 0.0, 0.15),
    },  # fmt: skip
    # touched, not held: leave before the fingers close, keep them open, move away
    "pick_up": _PRE_GRASP,
    "grasp": _PRE_GRASP,
    # any "<verb>_start" (touched the handle or knob, not started moving it): leave before
    # the fingers close and stay at the part, the fingers open, jittering a little and
    # lifting ~1 cm so they do not push it. (Backing the hand off 10-30 cm, as before,
    # ended the "contact" videos below the "approach" ones: the hand's distance to the
    # part is what separates the two levels' progress; docs/generate.md)
    "start": {
        "milestone_cut": (0.4, 0.9),
        "terminal_grip": "open",
        "terminal_w": (6, 14),
        "scale": (0.05, 0.15),
        "terminal_drift": (0.0, 0.0, 0.05),
    },  # fmt: skip
    "press": {
        "milestone_cut": (0.2, 0.7),
        "terminal_grip": "open",
        "terminal_w": (8, 20),
        "scale": (0.15, 0.4),
    },  # fmt: skip
    # picked up, grasp not kept: let go within a frame of the lift, lowering the hand so
    # the object is set back down (a drop from the lift topples tall items and rolls cans)
    "carry": {
        "milestone_cut": (0.0, 0.5),
        "terminal_grip": "open",
        "terminal_w": (8, 16),
        "scale": (0.0, 0.1),
        "terminal_drift": (0.0, 0.0, -0.5),
    },  # fmt: skip
    # carried, not over the target yet / over it, not released: keep holding, move little
    "approach_goal": {
        "milestone_cut": (0.0, 0.4),
        "terminal_grip": "close",
        "terminal_w": (8, 20),
        "scale": (0.05, 0.2),
        "terminal_drift": (0.0, 0.0, 0.3),
    },  # fmt: skip
    "place": {
        "milestone_cut": (0.1, 0.6),
        "terminal_grip": "close",
        "terminal_w": (8, 20),
        "scale": (0.1, 0.25),
    },  # fmt: skip
    # started, not finished: keep the handle (letting go undoes the grasp), move little
    "finish": {
        "milestone_cut": (0.1, 0.5),
        "terminal_grip": "close",
        "terminal_w": (8, 20),
        "scale": (0.1, 0.3),
    },  # fmt: skip
}
_DEFAULT_ENDING = {"milestone_cut": (0.2, 0.7), "terminal_grip": "keep", "terminal_w": (10, 25),
                   "scale": (0.2, 0.5)}  # fmt: skip


def component_kind(component: str) -> str:
    """The ending family of a milestone component: ``"open_start:drawer"`` -> "start"."""
    kind = component.partition(":")[0]
    for suffix in ("_start", "_finish"):
        if kind.endswith(suffix):
            return suffix[1:]
    return kind


def by_milestone(
    levels: Sequence[LevelSpec],
    components: Sequence[str],
    endings: Mapping[str, dict] | None = None,
) -> list[LevelSpec]:
    """Levels cut by milestone: level L leaves the expert between the demo's achievement
    of component L-1 and of component L, with the ending `ENDINGS_BY_KIND` gives
    component L's kind. The subtask-fraction knobs stay as the fallback, so a level
    still plans without a demo's milestone steps. ``endings`` replaces the ending of
    some kinds for one task group (free objects need other endings than handles: see
    `rover.sim.tasks._common.PICK_PLACE_ENDINGS`)."""
    table = {**ENDINGS_BY_KIND, **(endings or {})}
    out = []
    for lv in levels:
        if lv.completes or lv.level - 1 >= len(components):
            out.append(lv)
            continue
        knobs = table.get(component_kind(components[lv.level - 1]), _DEFAULT_ENDING)
        out.append(lv.model_copy(update=dict(knobs)))
    return out


def plan_seed(seed: int, task: str, index: int) -> np.random.Generator:
    """The Generator for video ``index`` of ``task``: stable across runs and processes.

    Python's ``hash`` of a string changes per process, so the task name enters through
    CRC32 instead.
    """
    return np.random.default_rng([int(seed), zlib.crc32(task.encode("utf-8")), int(index)])


def level_schedule(levels: Sequence[LevelSpec], per_level: int) -> list[tuple[int, LevelSpec]]:
    """``(index, level)`` pairs for ``per_level`` videos of every level, lowest level first.

    The index is the video's number within the task; feed it to `plan_seed` so each
    video's plan is deterministic and independent of how many videos other levels get.
    """
    if per_level < 0:
        raise ValueError(f"per_level must be >= 0, got {per_level}")
    out: list[tuple[int, LevelSpec]] = []
    for spec in sorted(levels, key=lambda s: s.level):
        for k in range(per_level):
            out.append((spec.level * 10_000 + k, spec))
    return out
