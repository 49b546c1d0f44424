"""Per-frame predictions and per-episode scores as tables for pandas users.

`predictions.csv`: one row per (episode, variant, frame) with the prediction, the ground
truth at that frame and the judge's verdict. `episodes.csv`: metrics.json's per-trace
rows (every per-video number, the same the page shows). Both also as parquet when
pyarrow is installed. Model text is written as data (the csv module quotes it).
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

from rover.report.run import RunData

PREDICTION_COLUMNS = [
    "episode_id",
    "variant",
    "label",
    "method",
    "backend",
    "view",
    "dataset",
    "frame_index",
    "position",
    "progress",
    "predicted",
    "truth_progress",
    "truth_source",
    "subtask_path",
    "description",
    "verdict",
]


def prediction_rows(run: RunData) -> list[dict[str, Any]]:
    out = []
    for e in run.entries:
        t = e.trace
        ep = run.episodes.get(t.episode_id)
        truth = {}
        if ep is not None and ep.truth is not None:
            truth = {ix: 100 * p for ix, p in zip(ep.frame_indices, ep.truth.progress, strict=True)}
        verdicts = run.verdicts.get(e.key, {})
        for f in t.frames:
            out.append(
                {
                    "episode_id": t.episode_id,
                    "variant": e.variant_id,
                    "label": e.label,
                    "method": t.method,
                    "backend": t.backend,
                    "view": e.view,
                    "dataset": e.row.get("dataset"),
                    "frame_index": f.index,
                    "position": f.position,
                    "progress": f.progress,
                    "predicted": f.predicted,
                    "truth_progress": truth.get(f.index),
                    "truth_source": ep.truth.progress_source if ep and ep.truth else None,
                    "subtask_path": " › ".join(f.subtask_path),
                    "description": f.description or "",
                    "verdict": verdicts[f.index].verdict if f.index in verdicts else None,
                }
            )
    return out


def episode_rows(run: RunData) -> list[dict[str, Any]]:
    """Scalar columns of metrics.json's per-trace rows (lists such as qa_dts left out)."""
    rows = run.metrics.get("per_trace", [])
    return [{k: v for k, v in r.items() if not isinstance(v, list | dict)} for r in rows]


def write_exports(run: RunData, out: Path) -> dict[str, Any]:
    """Write the tables into `out`; return their hrefs for the page."""
    preds, eps = prediction_rows(run), episode_rows(run)
    _csv(out / "predictions.csv", preds, PREDICTION_COLUMNS)
    ep_cols = list(dict.fromkeys(k for r in eps for k in r))
    _csv(out / "episodes.csv", eps, ep_cols)
    extra = []
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        pa = None
    if pa is not None:
        for name, rows, cols in (
            ("predictions", preds, PREDICTION_COLUMNS),
            ("episodes", eps, ep_cols),
        ):
            table = pa.Table.from_pylist([{c: r.get(c) for c in cols} for r in rows])
            pq.write_table(table, out / f"{name}.parquet")
            extra.append((f"{name}.parquet", f"{name}.parquet"))
    return {"predictions": "predictions.csv", "episodes": "episodes.csv", "extra": extra}


def _csv(path: Path, rows: list[dict[str, Any]], columns: list[str]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=columns, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    tmp.replace(path)
