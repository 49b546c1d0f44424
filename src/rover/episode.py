"""The Episode: one video of one task attempt, shared by every part of rover.

Sources (`rover.io`, `rover.sim`) produce Episodes, methods consume them, the evaluation
compares traces against their ground truth. Pixels live in `views` (never serialised);
everything else round-trips through `episode.json` in a dataset directory.

Frame positions vs frame indices: `views[v][t]` is the t-th *sampled* frame; its index in
the original recording is `frame_indices[t]`. Ground truth arrays are per sampled frame,
and every ground-truth frame reference (subtask bounds, events, QA) is a *position*
t in 0..num_frames-1. Metrics align predictions to truth by original index, never by
loop position, so subsampling an episode never shifts the comparison.
"""

from __future__ import annotations

from enum import StrEnum
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from rover.errors import InputError

SCHEMA_VERSION = 1


class StateType(StrEnum):
    """How a frame's state was produced (paper Sec. 4.1)."""

    expert = "expert"
    non_expert = "non_expert"
    interpolating = "interpolating"


class Subtask(BaseModel):
    """One ground-truth object-centric subtask, spanning positions start..end inclusive."""

    name: str
    start: int
    end: int
    object: str | None = None


class Event(BaseModel):
    """Something that happened (or was expected and never did: frame is None)."""

    name: str  # contact, grasp, pick_up, drop, place, open_start, open_finish, press, ...
    object: str | None = None
    frame: int | None = None  # position of the first frame showing the event


class QAItem(BaseModel):
    """A templated video question (App. C.3) with its ground-truth answer."""

    question: str
    answer: bool
    frame: int | None = None  # position where the answer becomes true, when it does
    template: str = ""  # template id, e.g. "did_pick_up"
    event: str | None = None
    object: str | None = None


class ObjectFacts(BaseModel):
    """What the simulator knows about one object at one frame."""

    position: tuple[float, float, float] | None = None
    lifted: bool = False
    inside: str | None = None  # the receptacle/region it is in ("bin 2", "drawer")
    on: str | None = None  # the surface/object it rests on
    reach: float | None = None  # m from the gripper to the point it is taken by (handle)
    goal_distance: float | None = None  # m (table plane) from the object to its goal point


class FrameFacts(BaseModel):
    """Structured simulator facts for one frame: what a frame description is judged against."""

    gripper: Literal["open", "closed"] = "open"
    gripper_opening: float | None = None  # 0 = fully closed, 1 = fully open
    contacts: list[str] = Field(default_factory=list)  # objects the gripper touches
    holding: str | None = None
    objects: dict[str, ObjectFacts] = Field(default_factory=dict)
    # articulated parts: door/drawer opening fraction 0..1, knob fraction of full turn,
    # button 1.0 when pressed; keys are part names ("door", "drawer", "knob", "button")
    articulations: dict[str, float] = Field(default_factory=dict)
    pressed: list[str] = Field(default_factory=list)
    distances: dict[str, float] = Field(default_factory=dict)  # e.g. "gripper-can": 0.12 m
    eef: tuple[float, float, float] | None = None  # gripper (end effector) position, m
    robot_contacts: list[str] = Field(default_factory=list)  # objects any robot part touches


class GroundTruth(BaseModel):
    """Everything known about the attempt, per sampled frame position."""

    progress: list[float]  # in [0, 1]
    state_type: list[StateType] | None = None
    subtasks: list[Subtask] = Field(default_factory=list)
    events: list[Event] = Field(default_factory=list)
    facts: list[FrameFacts] | None = None
    level: int | None = None
    qa: list[QAItem] = Field(default_factory=list)
    # "simulation" for generated value functions, "frame_number" for real videos where
    # normalised time is the only truth we have (App. L).
    progress_source: Literal["simulation", "frame_number", "annotation"] = "simulation"

    @field_validator("progress")
    @classmethod
    def _progress_in_range(cls, v: list[float]) -> list[float]:
        bad = [p for p in v if not (-1e-6 <= p <= 1 + 1e-6) or p != p]
        if bad:
            raise ValueError(f"progress values must lie in [0, 1], got {bad[0]!r}")
        return v

    def at_positions(self, positions: list[int]) -> GroundTruth:
        """Ground truth restricted to the given sampled positions (kept in order)."""
        remap = _position_remapper(positions)
        return GroundTruth(
            progress=[self.progress[p] for p in positions],
            state_type=None if self.state_type is None else [self.state_type[p] for p in positions],
            subtasks=[
                s.model_copy(update={"start": remap(s.start, "ceil"), "end": remap(s.end, "floor")})
                for s in self.subtasks
            ],
            events=[
                e.model_copy(update={"frame": None if e.frame is None else remap(e.frame, "ceil")})
                for e in self.events
            ],
            facts=None if self.facts is None else [self.facts[p] for p in positions],
            level=self.level,
            qa=[
                q.model_copy(update={"frame": None if q.frame is None else remap(q.frame, "ceil")})
                for q in self.qa
            ],
            progress_source=self.progress_source,
        )


def _position_remapper(positions: list[int]):
    """Map an old position to the nearest kept position at/after ('ceil') or before it."""
    arr = np.asarray(positions)

    def remap(old: int, how: str) -> int:
        if how == "ceil":
            k = int(np.searchsorted(arr, old, side="left"))
            return min(k, len(arr) - 1)
        k = int(np.searchsorted(arr, old, side="right")) - 1
        return max(k, 0)

    return remap


class Episode(BaseModel):
    """One task attempt: metadata, optional ground truth, and the frames of each view."""

    model_config = ConfigDict(arbitrary_types_allowed=True)

    schema_version: int = SCHEMA_VERSION
    id: str
    task: str
    task_group: str | None = None
    source: str | None = None  # where it came from: "sim:Lift", "lerobot:/path", a file...
    fps: float = 30.0
    frame_indices: list[int]  # original index of each sampled frame
    view_names: list[str]
    default_view: str | None = None
    truth: GroundTruth | None = None
    extra: dict[str, Any] = Field(default_factory=dict)
    # name -> uint8 array (T, H, W, 3); not serialised (lives in the MP4s / source files)
    views: dict[str, np.ndarray] = Field(default_factory=dict, exclude=True, repr=False)

    @model_validator(mode="after")
    def _consistent(self) -> Episode:
        n = len(self.frame_indices)
        if n == 0:
            raise ValueError(f"episode {self.id!r} has zero frames")
        if any(b <= a for a, b in zip(self.frame_indices, self.frame_indices[1:], strict=False)):
            raise ValueError(f"episode {self.id!r}: frame_indices must be strictly increasing")
        if self.truth is not None:
            if len(self.truth.progress) != n:
                got = len(self.truth.progress)
                raise ValueError(f"episode {self.id!r}: {got} progress values for {n} frames")
            if self.truth.state_type is not None and len(self.truth.state_type) != n:
                raise ValueError(f"episode {self.id!r}: state_type length != {n} frames")
            if self.truth.facts is not None and len(self.truth.facts) != n:
                raise ValueError(f"episode {self.id!r}: facts length != {n} frames")
        for name, arr in self.views.items():
            if arr.ndim != 4 or arr.shape[-1] != 3 or arr.dtype != np.uint8:
                raise ValueError(f"view {name!r} must be uint8 (T, H, W, 3), got {arr.shape}")
            if arr.shape[0] != n:
                raise ValueError(f"view {name!r} has {arr.shape[0]} frames, expected {n}")
        return self

    @property
    def num_frames(self) -> int:
        return len(self.frame_indices)

    @property
    def view(self) -> str:
        """The view methods look at unless told otherwise."""
        if self.default_view:
            return self.default_view
        return self.view_names[0]

    def frames(self, view: str | None = None) -> np.ndarray:
        """Pixels of one view, (T, H, W, 3) uint8."""
        name = view or self.view
        if name not in self.views:
            if name not in self.view_names:
                raise InputError(
                    f"episode {self.id!r} has no view {name!r}; views: {', '.join(self.view_names)}"
                )
            raise InputError(f"episode {self.id!r}: frames of view {name!r} were not loaded")
        return self.views[name]

    def select(self, positions: list[int]) -> Episode:
        """A new Episode holding only the given sampled positions (truth remapped)."""
        if not positions:
            raise InputError("cannot select zero frames")
        if sorted(set(positions)) != list(positions):
            raise ValueError("positions must be strictly increasing")
        return self.model_copy(
            update={
                "frame_indices": [self.frame_indices[p] for p in positions],
                "truth": None if self.truth is None else self.truth.at_positions(positions),
                "views": {k: v[positions] for k, v in self.views.items()},
            }
        )

    def subsample(self, n: int | None) -> Episode:
        """Keep n frames spread evenly, always including the first and the last."""
        if n is None or n >= self.num_frames:
            return self
        return self.select(even_positions(self.num_frames, n))

    def with_view(self, view: str) -> Episode:
        """The same attempt seen from one named view (for per-view evaluation)."""
        self.frames(view)  # validates
        return self.model_copy(update={"default_view": view})

    def resized(self, size: int | None) -> Episode:
        """Frames scaled so the long side is `size` px (never upscaled)."""
        if size is None:
            return self
        from rover.io.frames import resize_long_side

        return self.model_copy(
            update={"views": {k: resize_long_side(v, size) for k, v in self.views.items()}}
        )


def even_positions(total: int, n: int) -> list[int]:
    """n positions spread evenly over range(total), first and last always included."""
    if n <= 0:
        raise InputError(f"--frames must be positive, got {n}")
    if n >= total:
        return list(range(total))
    if n == 1:
        return [0]
    pos = np.round(np.linspace(0, total - 1, n)).astype(int)
    return [int(p) for p in pos]
