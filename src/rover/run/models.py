"""Typed views of the run directory's JSON files, with a schema version.

The models check the shape of what every reader relies on and let everything else
through (`extra="allow"`), so a run written by a newer rover with more fields still
reads. `SCHEMA_VERSION` counts changes in meaning: version 2 made every rate a
percentage and QA a per-video mean; a version-1 `metrics.json` is rescored from the
run's files rather than misread.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from rover.run import SCHEMA_VERSION


class _Open(BaseModel):
    model_config = ConfigDict(extra="allow")


class VariantModel(_Open):
    id: str
    method: str
    backend: str
    frames: int | None = None
    window: int | None = None
    view: str | None = None
    label: str = ""


class RunConfig(_Open):
    """run.json: what the run was asked to do."""

    schema_version: int = 1
    dataset: str | None = None
    sources: list[str] = Field(default_factory=list)
    episodes: list[str] = Field(default_factory=list)
    episode_datasets: dict[str, str | None] = Field(default_factory=dict)
    methods: list[str] = Field(default_factory=list)
    backends: list[str] = Field(default_factory=list)
    judge: str = "rule"
    answerer: str = "rule"
    variants: list[VariantModel] = Field(default_factory=list)


class TraceRow(_Open):
    """One (episode, variant) row of metrics.json: every per-video number."""

    episode_id: str
    variant: str
    method: str
    label: str = ""
    error: str | None = None


class Aggregate(_Open):
    table: str
    by: str
    group: Any
    variant: str
    metric: str
    mean: float | None = None
    se: float | None = None
    n: int = 0


class Metrics(_Open):
    """metrics.json: computed once by the scorer, only displayed by every view."""

    schema_version: int = SCHEMA_VERSION
    variants: list[VariantModel] = Field(default_factory=list)
    per_trace: list[TraceRow] = Field(default_factory=list)
    aggregates: list[Aggregate] = Field(default_factory=list)
    qa_pooled: list[dict[str, Any]] = Field(default_factory=list)
    cost: list[dict[str, Any]] = Field(default_factory=list)
    error_analysis: list[dict[str, Any]] = Field(default_factory=list)
    counts: dict[str, Any] = Field(default_factory=dict)
    notes: list[str] = Field(default_factory=list)
    judges: dict[str, Any] = Field(default_factory=dict)
