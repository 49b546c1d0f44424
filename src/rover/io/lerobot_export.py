"""Write a rover dataset directory as a LeRobot v3.0 dataset (`rover export --format lerobot`).

Layout (field by field as LeRobot v3.0 publishes it; see docs/sources.md)::

    meta/info.json                       codebase_version "v3.0", fps, features, paths, totals
    meta/tasks.parquet                   task strings (pandas index "task") and task_index
    meta/stats.json                      min/max/mean/std/count of every feature (normalisation)
    meta/episodes/chunk-000/file-000.parquet
                                         one row per episode: where its rows and frames lie,
                                         plus rover's episode truth under "rover/..."
    data/chunk-000/file-000.parquet      one row per frame of every episode
    videos/observation.images.<view>/chunk-000/file-000.mp4
                                         every episode of one camera, back to back

Ground truth travels with the frames: per-frame features `progress` (0..1, float64),
`state_type` (index into STATE_TYPES, -1 unknown), `subtask_index` (-1 outside every
subtask), `level` (-1 unknown) and `source_frame_index` (the frame's index in the
original rollout); the episode table holds the QA items, subtasks, events and simulator
facts. Videos are remuxed, not re-encoded: every packet is copied and only re-timed to
the dataset's single frame rate, so decoding the export gives the very same pixels.
"""

from __future__ import annotations

import json
import shutil
import statistics
from fractions import Fraction
from pathlib import Path
from typing import Any

import av

from rover.episode import Episode, StateType
from rover.errors import InputError
from rover.io.dataset import episode_ids, read_dataset_info, read_episode
from rover.io.lerobot_stats import (
    as_json,
    column_stats,
    episode_columns,
    merge_stats,
    video_stats,
)

CODEBASE_VERSION = "v3.0"
CHUNKS_SIZE = 1000  # LeRobot's DEFAULT_CHUNK_SIZE
DATA_FILES_SIZE_IN_MB = 100  # LeRobot's DEFAULT_DATA_FILE_SIZE_IN_MB
VIDEO_FILES_SIZE_IN_MB = 500  # LeRobot's DEFAULT_VIDEO_FILE_SIZE_IN_MB
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
EPISODES_PATH = "meta/episodes/chunk-000/file-000.parquet"
TASKS_PATH = "meta/tasks.parquet"
STATS_PATH = "meta/stats.json"
STATE_TYPES = [s.value for s in StateType]
CAMERA_PREFIX = "observation.images."
TRUTH_FEATURES = ("progress", "state_type", "subtask_index", "level", "source_frame_index")
_TICKS_PER_FRAME = 100  # output video time base: 1 / (fps * 100)


def camera_key(view: str) -> str:
    return CAMERA_PREFIX + view


def export_lerobot(root: Path, out: Path, fps: int | None = None) -> dict[str, Any]:
    """Export the rover dataset at `root` to `out` (must not exist); returns info.json.

    Raises:
        InputError: not a rover dataset, episodes with different views or frame sizes,
            `out` already exists, a video that cannot be remuxed.
    """
    root, out = Path(root), Path(out)
    info = read_dataset_info(root)
    ids = episode_ids(root)
    if not ids:
        raise InputError(f"{root}: no complete episodes to export")
    if out.exists() and any(out.iterdir()):
        raise InputError(f"--out {out} exists and is not empty; choose a new folder")
    episodes = [read_episode(root, i, load_frames=False) for i in ids]
    views = episodes[0].view_names
    for ep in episodes:
        if ep.view_names != views:
            raise InputError(
                f"episode {ep.id!r} has views {ep.view_names}, episode {ids[0]!r} has {views}: "
                "a LeRobot dataset has one set of cameras"
            )
    rate = fps or max(1, round(statistics.median(ep.fps for ep in episodes)))
    if rate <= 0:
        raise InputError(f"--fps must be positive, got {rate}")
    tmp = out.with_name(out.name + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    sizes = {}
    for view in views:
        files = [root / "episodes" / ep.id / f"{view}.mp4" for ep in episodes]
        sizes[view] = _remux(
            files,
            tmp / VIDEO_PATH.format(video_key=camera_key(view), chunk_index=0, file_index=0),
            rate,
        )
    tasks = list(dict.fromkeys(ep.task for ep in episodes))
    starts = _starts([ep.num_frames for ep in episodes])
    cols = _write_data(tmp, episodes, tasks, starts, rate)
    per_episode = _episode_stats(root, episodes, views, starts, cols)
    _write_episodes(tmp, episodes, views, starts, rate, per_episode)
    _write_stats(tmp, per_episode)
    _write_tasks(tmp, tasks)
    meta = _info(info.name, episodes, views, sizes, tasks, rate)
    (tmp / "meta" / "info.json").write_text(json.dumps(meta, indent=4))
    if out.exists():
        out.rmdir()
    tmp.replace(out)
    return meta


def _starts(lengths: list[int]) -> list[int]:
    out, total = [], 0
    for n in lengths:
        out.append(total)
        total += n
    return out


# ---- videos --------------------------------------------------------------------------


def _remux(files: list[Path], dest: Path, fps: int) -> tuple[int, int]:
    """Copy every packet of `files` into one MP4, re-timed to `fps`; (height, width)."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    tb = Fraction(1, fps * _TICKS_PER_FRAME)
    offset = 0  # frames written so far
    size = None
    try:
        with av.open(str(dest), "w", format="mp4") as oc:
            ostream = None
            for path in files:
                with av.open(str(path)) as ic:
                    stream = ic.streams.video[0]
                    here = (
                        stream.codec_context.height,
                        stream.codec_context.width,
                        stream.codec_context.name,
                    )
                    if ostream is None:
                        ostream = oc.add_stream_from_template(stream)
                        ostream.time_base = tb
                        size = here
                    elif here != size:
                        raise InputError(
                            f"{path}: {here[1]}x{here[0]} {here[2]} video, the first "
                            f"episode's is {size[1]}x{size[0]} {size[2]}: one format per camera"
                        )
                    packets = [p for p in ic.demux(stream) if p.dts is not None and p.size]
                    first = min(p.pts for p in packets)
                    step = _frame_step(packets, path)
                    for p in packets:
                        p.pts = (offset + round((p.pts - first) / step)) * _TICKS_PER_FRAME
                        p.dts = (offset + round((p.dts - first) / step)) * _TICKS_PER_FRAME
                        p.time_base = tb
                        p.stream = ostream
                        oc.mux(p)
                    offset += len(packets)
    except av.error.FFmpegError as exc:
        raise InputError(f"{dest}: cannot remux ({exc.__class__.__name__}: {exc})") from exc
    assert size is not None
    return size[0], size[1]


def _frame_step(packets: list, path: Path) -> int:
    """The constant pts step of a video (rover writes constant frame rate)."""
    pts = sorted(p.pts for p in packets)
    steps = {b - a for a, b in zip(pts, pts[1:], strict=False)}
    if len(steps) > 1:
        raise InputError(f"{path}: variable frame timing; cannot remux without re-encoding")
    return steps.pop() if steps else 1


# ---- tables --------------------------------------------------------------------------


def _subtask_of(ep: Episode, pos: int) -> int:
    if ep.truth is None:
        return -1
    for j, s in enumerate(ep.truth.subtasks):
        if s.start <= pos <= s.end:
            return j
    return -1


def _write_data(
    tmp: Path, episodes: list[Episode], tasks: list[str], starts, fps
) -> dict[str, list]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    cols: dict[str, list] = {k: [] for k in _frame_columns()}
    for e, (ep, start) in enumerate(zip(episodes, starts, strict=True)):
        truth = ep.truth
        for pos, original in enumerate(ep.frame_indices):
            cols["timestamp"].append(pos / fps)
            cols["frame_index"].append(pos)
            cols["episode_index"].append(e)
            cols["index"].append(start + pos)
            cols["task_index"].append(tasks.index(ep.task))
            cols["progress"].append(truth.progress[pos] if truth else None)
            states = truth.state_type if truth else None
            cols["state_type"].append(STATE_TYPES.index(states[pos]) if states else -1)
            cols["subtask_index"].append(_subtask_of(ep, pos))
            cols["level"].append(truth.level if truth and truth.level is not None else -1)
            cols["source_frame_index"].append(original)
    schema = pa.schema([(k, t) for k, t in _frame_columns().items()])
    path = tmp / DATA_PATH.format(chunk_index=0, file_index=0)
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.table(cols, schema=schema), path)
    return cols


def _episode_stats(root: Path, episodes: list[Episode], views, starts, cols) -> list[dict]:
    """Each episode's normalisation stats: its frame columns and a sample of its videos."""
    out = []
    for ep, start in zip(episodes, starts, strict=True):
        stats = {}
        for key, values in cols.items():
            st = column_stats(values[start : start + ep.num_frames])
            if st is not None:
                stats[key] = st
        for view in views:
            path = root / "episodes" / ep.id / f"{view}.mp4"
            stats[camera_key(view)] = video_stats(path, ep.num_frames)
        out.append(stats)
    return out


def _write_stats(tmp: Path, per_episode: list[dict]) -> None:
    keys = dict.fromkeys(k for st in per_episode for k in st)
    merged = {k: merge_stats([st[k] for st in per_episode if k in st]) for k in keys}
    (tmp / STATS_PATH).write_text(json.dumps(as_json(merged), indent=4))


def _frame_columns() -> dict[str, Any]:
    import pyarrow as pa

    return {
        "timestamp": pa.float32(),
        "frame_index": pa.int64(),
        "episode_index": pa.int64(),
        "index": pa.int64(),
        "task_index": pa.int64(),
        "progress": pa.float64(),
        "state_type": pa.int64(),
        "subtask_index": pa.int64(),
        "level": pa.int64(),
        "source_frame_index": pa.int64(),
    }


def _write_episodes(
    tmp: Path, episodes: list[Episode], views, starts, fps, per_episode: list[dict]
) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = []
    for e, (ep, start, stats) in enumerate(zip(episodes, starts, per_episode, strict=True)):
        n = ep.num_frames
        truth = ep.truth
        row: dict[str, Any] = {
            "episode_index": e,
            "tasks": [ep.task],
            "length": n,
            "data/chunk_index": 0,
            "data/file_index": 0,
            "dataset_from_index": start,
            "dataset_to_index": start + n,
        }
        for view in views:
            key = camera_key(view)
            row[f"videos/{key}/chunk_index"] = 0
            row[f"videos/{key}/file_index"] = 0
            row[f"videos/{key}/from_timestamp"] = start / fps
            row[f"videos/{key}/to_timestamp"] = (start + n) / fps
        row["meta/episodes/chunk_index"] = 0
        row["meta/episodes/file_index"] = 0
        row["rover/episode_id"] = ep.id
        row["rover/task_group"] = ep.task_group
        row["rover/source"] = ep.source
        row["rover/fps"] = float(ep.fps)
        row["rover/level"] = truth.level if truth else None
        row["rover/progress_source"] = truth.progress_source if truth else None
        row["rover/subtasks"] = [s.model_dump() for s in truth.subtasks] if truth else []
        row["rover/events"] = [x.model_dump() for x in truth.events] if truth else []
        row["rover/qa"] = [q.model_dump() for q in truth.qa] if truth else []
        facts = truth.facts if truth else None
        row["rover/facts"] = (
            json.dumps([f.model_dump(mode="json") for f in facts]) if facts is not None else None
        )
        row.update(episode_columns(stats))
        rows.append(row)
    path = tmp / EPISODES_PATH
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.Table.from_pylist(rows), path)


def _write_tasks(tmp: Path, tasks: list[str]) -> None:
    """tasks.parquet as pandas writes it: task strings are the index, named "task"."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table({"task_index": list(range(len(tasks))), "task": tasks})
    pandas_meta = {
        "index_columns": ["task"],
        "column_indexes": [],
        "columns": [
            {
                "name": "task_index",
                "field_name": "task_index",
                "pandas_type": "int64",
                "numpy_type": "int64",
                "metadata": None,
            },
            {
                "name": "task",
                "field_name": "task",
                "pandas_type": "unicode",
                "numpy_type": "object",
                "metadata": None,
            },
        ],
        "creator": {"library": "pyarrow", "version": pa.__version__},
        "pandas_version": "2.2.0",
    }
    table = table.replace_schema_metadata({b"pandas": json.dumps(pandas_meta).encode()})
    pq.write_table(table, tmp / TASKS_PATH)


def _info(name, episodes, views, sizes, tasks, fps) -> dict[str, Any]:
    n_frames = sum(ep.num_frames for ep in episodes)
    scalar = {"shape": [1], "names": None}
    features: dict[str, Any] = {}
    for view in views:
        h, w = sizes[view]
        features[camera_key(view)] = {
            "dtype": "video",
            "shape": [h, w, 3],
            "names": ["height", "width", "channels"],
            "info": {
                "video.height": h,
                "video.width": w,
                "video.codec": "h264",
                "video.pix_fmt": "yuv420p",
                "video.is_depth_map": False,
                "video.fps": fps,
                "video.channels": 3,
                "has_audio": False,
            },
        }
    features.update(
        {
            "timestamp": {"dtype": "float32", **scalar},
            "frame_index": {"dtype": "int64", **scalar},
            "episode_index": {"dtype": "int64", **scalar},
            "index": {"dtype": "int64", **scalar},
            "task_index": {"dtype": "int64", **scalar},
            "progress": {"dtype": "float64", **scalar},
            "state_type": {"dtype": "int64", **scalar},
            "subtask_index": {"dtype": "int64", **scalar},
            "level": {"dtype": "int64", **scalar},
            "source_frame_index": {"dtype": "int64", **scalar},
        }
    )
    return {
        "codebase_version": CODEBASE_VERSION,
        "robot_type": "panda",
        "total_episodes": len(episodes),
        "total_frames": n_frames,
        "total_tasks": len(tasks),
        "chunks_size": CHUNKS_SIZE,
        "data_files_size_in_mb": DATA_FILES_SIZE_IN_MB,
        "video_files_size_in_mb": VIDEO_FILES_SIZE_IN_MB,
        "fps": fps,
        "splits": {"train": f"0:{len(episodes)}"},
        "data_path": DATA_PATH,
        "video_path": VIDEO_PATH,
        "features": features,
        "rover": {"dataset": name, "state_types": STATE_TYPES},
    }
