"""The two annotation tables, built from traces (one fact, one place: the trace).

frames.parquet   one row per annotated frame, keyed by (episode_index, frame_index):
                 progress (0-100, full task), subtask_path (list of str), description,
                 predicted (False where the value was carried forward), method, backend,
                 model, episode_id
episodes.parquet one row per episode: episode_index, episode_id, task, num_frames, voc,
                 final_progress, success (final_progress >= success_threshold),
                 success_threshold, calls (cached_calls of them answered from the response
                 cache), tokens, parse_failures, method, backend, model

`in_place_table` is the frames table in the shape LeRobot's reward annotations take
beside a dataset: a global `index`, `episode_index`, `frame_index`, and the progress
also as `progress_sparse` in [0, 1], the column LeRobot's RA-BC sample weighting reads.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from rover.eval.cost import trace_totals
from rover.eval.progress_metrics import filled_predictions, voc
from rover.methods.trace import Trace

FRAMES_FILE = "frames.parquet"
EPISODES_FILE = "episodes.parquet"
IN_PLACE_FILE = "rover_progress.parquet"


def frame_rows(trace: Trace, episode_index: int) -> list[dict[str, Any]]:
    """One row per frame of the trace, progress filled forward where none was predicted."""
    progress = filled_predictions(trace)
    return [
        {
            "episode_index": episode_index,
            "frame_index": f.index,
            "progress": float(p),
            "subtask_path": list(f.subtask_path),
            "description": f.description or "",
            "predicted": bool(f.predicted),
            "method": trace.method,
            "backend": trace.backend,
            "model": trace.model,
            "episode_id": trace.episode_id,
        }
        for f, p in zip(trace.frames, progress, strict=True)
    ]


def episode_row(trace: Trace, episode_index: int, success_threshold: float) -> dict[str, Any]:
    """The per-episode summary used to filter a dataset (VOC, final progress, success)."""
    progress = filled_predictions(trace)
    score, _ = voc(np.asarray(progress, float))
    final = float(progress[-1]) if progress else 0.0
    totals = trace_totals(trace)
    return {
        "episode_index": episode_index,
        "episode_id": trace.episode_id,
        "task": trace.task,
        "num_frames": trace.num_frames,
        "voc": None if math.isnan(score) else float(score),
        "final_progress": final,
        "success": final >= success_threshold,
        "success_threshold": float(success_threshold),
        "calls": totals.calls,
        "cached_calls": totals.cached_calls,
        "tokens": totals.total_tokens,
        "parse_failures": totals.parse_failures,
        "method": trace.method,
        "backend": trace.backend,
        "model": trace.model,
    }


def _frames_schema():
    import pyarrow as pa

    return pa.schema(
        [
            ("episode_index", pa.int64()),
            ("frame_index", pa.int64()),
            ("progress", pa.float64()),
            ("subtask_path", pa.list_(pa.string())),
            ("description", pa.string()),
            ("predicted", pa.bool_()),
            ("method", pa.string()),
            ("backend", pa.string()),
            ("model", pa.string()),
            ("episode_id", pa.string()),
        ]
    )


def _episodes_schema():
    import pyarrow as pa

    return pa.schema(
        [
            ("episode_index", pa.int64()),
            ("episode_id", pa.string()),
            ("task", pa.string()),
            ("num_frames", pa.int64()),
            ("voc", pa.float64()),
            ("final_progress", pa.float64()),
            ("success", pa.bool_()),
            ("success_threshold", pa.float64()),
            ("calls", pa.int64()),
            ("cached_calls", pa.int64()),
            ("tokens", pa.int64()),
            ("parse_failures", pa.int64()),
            ("method", pa.string()),
            ("backend", pa.string()),
            ("model", pa.string()),
        ]
    )


def frames_table(rows: list[dict[str, Any]]):
    import pyarrow as pa

    return pa.Table.from_pylist(rows, schema=_frames_schema())


def episodes_table(rows: list[dict[str, Any]]):
    import pyarrow as pa

    return pa.Table.from_pylist(rows, schema=_episodes_schema())


def in_place_table(rows: list[dict[str, Any]], offsets: dict[int, int]):
    """Frames rows for LeRobot's root: `index` = the dataset-wide frame index."""
    import pyarrow as pa

    table = frames_table(rows)
    index = [offsets.get(r["episode_index"], 0) + r["frame_index"] for r in rows]
    sparse = [r["progress"] / 100.0 for r in rows]
    table = table.add_column(0, "index", pa.array(index, pa.int64()))
    return table.append_column("progress_sparse", pa.array(sparse, pa.float64()))


def write_parquet_atomic(table, path: Path) -> None:
    """Write a parquet file under a temporary name, then rename: never half a table."""
    import pyarrow.parquet as pq

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, path)
