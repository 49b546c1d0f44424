"""The Trace: everything a method did on one episode, enough to redraw its figures.

Written as JSON by `rover reason` and by the evaluation runner (one file per episode and
method). Progress values are on 0..100 over the full task; frames are keyed by their
original frame index so traces of differently subsampled runs compare correctly.
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from pydantic import BaseModel, Field

if TYPE_CHECKING:
    from rover.episode import Episode

TRACE_SCHEMA_VERSION = 1


class FrameRecord(BaseModel):
    index: int  # original frame index
    position: int  # position among the sampled frames the method saw
    progress: float | None = None  # 0..100 over the full task (stitched, filled forward)
    description: str | None = None
    subtask_path: list[str] = Field(default_factory=list)  # root task excluded
    subtask_progress: float | None = None  # raw value the model gave for its line
    predicted: bool = False  # False when progress was filled forward, not answered


class CallRecord(BaseModel):
    id: int
    kind: str  # PromptMeta.kind
    frame_indices: list[int] = Field(default_factory=list)  # images sent, in order
    line_id: int | None = None  # ROVER: which line of reasoning made the call
    subtask_path: list[str] = Field(default_factory=list)
    prompt_tokens: int = 0
    completion_tokens: int = 0
    image_tokens: int = 0
    cached_prompt_tokens: int = 0  # part of prompt_tokens the provider had cached (its report)
    usage_source: Literal["reported", "estimated"] = "estimated"
    latency_s: float = 0.0
    cached: bool = False
    parse: Literal["ok", "retried", "failed"] = "ok"
    response: str = ""
    error: str | None = None
    max_tokens: int | None = None  # the completion budget sent with the call
    finish_reason: str | None = None  # as the provider said ("stop", "length", "MAX_TOKENS")
    truncated: bool = False  # the reply stopped at max_tokens
    reply_capped: bool = False  # longer than the parsers read (64 KB / 2,000 lines)


class LineNode(BaseModel):
    """One line of reasoning (ROVER): its subtask, its frames and its children."""

    id: int
    subtask: str
    depth: int
    first_frame: int  # original index of the line's first frame (its "initial robot scene")
    last_frame: int | None = None
    outcome: Literal["complete", "end_of_video", "guard", "failed", "running"] = "running"
    final_description: str | None = None
    children: list[LineNode] = Field(default_factory=list)
    first_position: int = 0  # sampled position of first_frame
    last_position: int | None = None
    planned_subtasks: list[str] = Field(default_factory=list)  # plan the model announced, if any
    calls: int = 0  # VLM calls this line made itself (children excluded)


class Totals(BaseModel):
    calls: int = 0
    cached_calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    image_tokens: int = 0
    cached_prompt_tokens: int = 0  # provider-reported prompt-prefix cache hits
    total_tokens: int = 0
    latency_s: float = 0.0
    parse_failures: int = 0
    parse_retries: int = 0
    truncated_replies: int = 0  # replies that stopped at their completion budget
    capped_replies: int = 0  # replies longer than the parsers read


class Trace(BaseModel):
    schema_version: int = TRACE_SCHEMA_VERSION
    method: str
    params: dict[str, Any] = Field(default_factory=dict)
    backend: str
    model: str
    oracle: bool = False  # True when answers came from ground truth, not a VLM
    episode_id: str
    task: str
    view: str | None = None
    num_frames: int
    frame_indices: list[int]
    frames: list[FrameRecord]
    tree: LineNode | None = None
    calls: list[CallRecord] = Field(default_factory=list)
    totals: Totals = Field(default_factory=Totals)
    started_at: str = Field(default_factory=lambda: datetime.now(UTC).isoformat())
    finished_at: str | None = None
    error: str | None = None

    @classmethod
    def start(
        cls,
        episode: Episode,
        method: str,
        params: dict[str, Any],
        backend: str,
        model: str,
        oracle: bool = False,
    ) -> Trace:
        """An empty trace for one run: one unpredicted FrameRecord per sampled frame."""
        return cls(
            method=method,
            params=dict(params),
            backend=backend,
            model=model,
            oracle=oracle,
            episode_id=episode.id,
            task=episode.task,
            view=episode.view,
            num_frames=episode.num_frames,
            frame_indices=list(episode.frame_indices),
            frames=[
                FrameRecord(index=idx, position=pos)
                for pos, idx in enumerate(episode.frame_indices)
            ],
        )

    def progress(self) -> list[float]:
        """Full-task progress per sampled frame (0..100), None replaced by 0."""
        return [f.progress if f.progress is not None else 0.0 for f in self.frames]

    def compute_totals(self) -> Totals:
        t = Totals()
        for c in self.calls:
            t.calls += 1
            t.cached_calls += int(c.cached)
            t.prompt_tokens += c.prompt_tokens
            t.completion_tokens += c.completion_tokens
            t.image_tokens += c.image_tokens
            t.cached_prompt_tokens += c.cached_prompt_tokens
            t.latency_s += c.latency_s
            t.parse_failures += int(c.parse == "failed")
            t.parse_retries += int(c.parse == "retried")
            t.truncated_replies += int(c.truncated)
            t.capped_replies += int(c.reply_capped)
        t.total_tokens = t.prompt_tokens + t.completion_tokens
        return t

    def save(self, path: Path) -> None:
        """Write atomically: a reader never sees half a trace."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(self.model_dump_json(indent=1))
        tmp.replace(path)

    @classmethod
    def load(cls, path: Path) -> Trace:
        return cls.model_validate_json(Path(path).read_text())
