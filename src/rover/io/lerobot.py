"""LeRobot datasets on local disk, format v2.x and v3.0, read without the lerobot package.

v2.x: one parquet file and one MP4 per camera per episode::

    meta/info.json        fps, features (camera keys have dtype "video" or "image"),
                          data_path / video_path templates with {episode_chunk},
                          {episode_index}, {video_key}; chunks_size
    meta/episodes.jsonl   {"episode_index": 0, "tasks": ["pick the cube"], "length": 250}
    meta/tasks.jsonl      {"task_index": 0, "task": "pick the cube"}
    data/chunk-000/episode_000000.parquet
    videos/chunk-000/<camera key>/episode_000000.mp4

v3.0: many episodes share one parquet file and one MP4 per camera; the episode table
says where each one lies::

    meta/info.json        templates with {chunk_index}, {file_index}, {video_key}
    meta/episodes/chunk-000/file-000.parquet   one row per episode: episode_index,
                          tasks, length, data/chunk_index, data/file_index,
                          videos/<key>/chunk_index, videos/<key>/file_index,
                          videos/<key>/from_timestamp, videos/<key>/to_timestamp
    meta/tasks.parquet    task strings (pandas index) and task_index
    data/chunk-000/file-000.parquet
    videos/<camera key>/chunk-000/file-000.mp4

Camera keys of dtype "image" (no videos) are PNG/JPEG bytes inside the data parquet.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, UnidentifiedImageError

from rover.episode import Episode
from rover.errors import InputError
from rover.io.frames import stack_frames, to_rgb_array
from rover.io.lerobot_truth import TRUTH_COLUMNS, carries_truth, rebuild_truth
from rover.io.plain import sample_positions
from rover.io.seek import VideoIndex, decode_frames, index_video
from rover.io.source import SourceReader

INFO = Path("meta/info.json")
EPISODES_V2 = Path("meta/episodes.jsonl")
TASKS_V2 = Path("meta/tasks.jsonl")
TASKS_V3 = Path("meta/tasks.parquet")


def _pq():
    import pyarrow.parquet as pq

    return pq


class LeRobotSource(SourceReader):
    """Episodes of a local LeRobot dataset; `view`/`?camera=` picks the camera key."""

    kind = "lerobot"

    def __init__(self, path: Path, **kwargs: Any) -> None:
        super().__init__(path, **kwargs)
        self.root = self.path
        self.info = _read_json(self.root / INFO, what="LeRobot dataset")
        self.version = str(self.info.get("codebase_version", "v2.0"))
        if not (self.version.startswith("v2") or self.version.startswith("v3")):
            raise InputError(
                f"{self.root / INFO}: codebase_version {self.version!r} is not supported "
                f"(rover reads v2.x and v3.0)"
            )
        features = self.info.get("features")
        if not isinstance(features, dict):
            raise InputError(f"{self.root / INFO}: missing or invalid field 'features'")
        self.cameras = [
            k
            for k, f in features.items()
            if isinstance(f, dict) and f.get("dtype") in ("video", "image")
        ]
        if not self.cameras:
            raise InputError(
                f"{self.root / INFO}: field 'features' has no camera (dtype video or image)"
            )
        self.camera = self._pick_camera()
        self.camera_dtype = features[self.camera]["dtype"]
        for key in ("fps", "data_path"):
            if key not in self.info:
                raise InputError(f"{self.root / INFO}: missing field {key!r}")
        if self.camera_dtype == "video" and not self.info.get("video_path"):
            raise InputError(f"{self.root / INFO}: missing field 'video_path'")
        self.chunks_size = int(self.info.get("chunks_size", 1000))
        if self.only_episode is not None and self.only_episode.isdigit():
            self.only_episode = f"episode_{int(self.only_episode):06d}"  # "?episode=3" works
        self._episodes = self._load_episode_table()
        self._tasks: dict[int, str] | None = None
        self._video_index: dict[Path, VideoIndex] = {}  # v3 files hold many episodes

    def _pick_camera(self) -> str:
        """The feature key for `view`: the full key, or its last dotted part (`wrist`)."""
        if self.view is None:
            return self.cameras[0]
        if self.view in self.cameras:
            return self.view
        short = [c for c in self.cameras if c.rsplit(".", 1)[-1] == self.view]
        if len(short) == 1:
            return short[0]
        shown = ", ".join(f"{c} ({c.rsplit('.', 1)[-1]})" for c in self.cameras)
        what = "several cameras end in" if short else "no camera"
        raise InputError(
            f"{self.root / INFO}: {what} {self.view!r} in 'features'; cameras: {shown}"
        )

    def global_offsets(self) -> dict[int, int]:
        """episode_index -> dataset-wide index of its first frame (LeRobot's `index`)."""
        offsets, running = {}, 0
        for idx, row in self._episodes.items():
            start = row.get("dataset_from_index")
            offsets[idx] = int(start) if start is not None else running
            running = offsets[idx] + int(row.get("length") or 0)
        return offsets

    def task_of(self, episode_id: str) -> str:
        if self.task is not None:
            return self.task
        idx, row = self._row(episode_id)
        return self._task_text(idx, row)

    def _index(self, video: Path) -> VideoIndex:
        if video not in self._video_index:
            self._video_index[video] = index_video(video)
        return self._video_index[video]

    # ---- episode table -------------------------------------------------------------

    def _load_episode_table(self) -> dict[int, dict[str, Any]]:
        if self.version.startswith("v2"):
            rows = _read_jsonl(self.root / EPISODES_V2)
        else:
            files = sorted((self.root / "meta" / "episodes").glob("chunk-*/file-*.parquet"))
            if not files:
                raise InputError(
                    f"{self.root / 'meta' / 'episodes'}: no episode files "
                    f"(expected chunk-*/file-*.parquet)"
                )
            rows = []
            for f in files:
                rows.extend(_read_parquet_rows(f, skip_prefix="stats/"))
        table: dict[int, dict[str, Any]] = {}
        for row in rows:
            if "episode_index" not in row:
                raise InputError(f"{self._episodes_file()}: a row has no field 'episode_index'")
            table[int(row["episode_index"])] = row
        return dict(sorted(table.items()))

    def _episodes_file(self) -> Path:
        return self.root / (EPISODES_V2 if self.version.startswith("v2") else "meta/episodes")

    def _episode_ids(self) -> list[str]:
        return [f"episode_{i:06d}" for i in self._episodes]

    def _row(self, episode_id: str) -> tuple[int, dict[str, Any]]:
        text = episode_id.removeprefix("episode_")
        if not text.isdigit() or int(text) not in self._episodes:
            raise InputError(f"{self.root}: no episode {episode_id!r}")
        idx = int(text)
        return idx, self._episodes[idx]

    # ---- reading -------------------------------------------------------------------

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        idx, row = self._row(episode_id)
        length = row.get("length")
        if self.camera_dtype == "video":
            video, offset, length = self._video_span(idx, row, length)
            positions = sample_positions(length, frames)
            pixels = decode_frames(video, [offset + p for p in positions], self._index(video))
        else:
            table = self._episode_data(idx, row, columns=[self.camera])
            images = table[self.camera]
            length = len(images)
            positions = sample_positions(length, frames)
            pixels = stack_frames(
                [self._decode_image(images[p], p) for p in positions],
                f"{self.root}: column {self.camera!r} of episode {idx}",
            )
        extra = {
            "total_frames": length,
            "dataset": self.root.name,
            "episode_index": idx,
            "robot_type": self.info.get("robot_type"),
            "codebase_version": self.version,
        }
        truth, indices = None, positions
        if carries_truth(self.info["features"], row):  # written by `rover export`
            data = self._episode_data(idx, row, columns=TRUTH_COLUMNS)
            names = (self.info.get("rover") or {}).get("state_types") or []
            truth = rebuild_truth(row, data, names).at_positions(positions)
            indices = [int(data["source_frame_index"][p]) for p in positions]
            extra["source_episode_id"] = row.get("rover/episode_id")
        return Episode(
            id=episode_id,
            task=self.task if self.task is not None else self._task_text(idx, row),
            task_group=row.get("rover/task_group"),
            source=f"lerobot:{self.root}",
            fps=self.fps or float(self.info["fps"]),
            frame_indices=indices,
            view_names=list(self.cameras),
            default_view=self.camera,
            views={self.camera: pixels},
            truth=truth,
            extra=extra,
        )

    def _video_span(self, idx: int, row: dict[str, Any], length: Any) -> tuple[Path, int, int]:
        """(video file, first frame of the episode in it, frame count)."""
        key = self.camera
        if self.version.startswith("v2"):
            rel = _format(
                self.info["video_path"],
                self.root / INFO,
                episode_chunk=idx // self.chunks_size,
                episode_index=idx,
                video_key=key,
            )
            video = self.root / rel
            if not video.exists():
                raise InputError(f"{video}: missing video of episode {idx}, camera {key!r}")
            vindex = self._index(video)
            n = vindex.num_frames if length is None else int(length)
            if n > vindex.num_frames:
                raise InputError(
                    f"{video}: {vindex.num_frames} frames but {EPISODES_V2} says length {n}"
                )
            return video, 0, n
        fields = [f"videos/{key}/{f}" for f in ("chunk_index", "file_index", "from_timestamp")]
        for f in fields:
            if row.get(f) is None:
                raise InputError(f"{self._episodes_file()}: episode {idx} has no field {f!r}")
        rel = _format(
            self.info["video_path"],
            self.root / INFO,
            chunk_index=int(row[fields[0]]),
            file_index=int(row[fields[1]]),
            video_key=key,
        )
        video = self.root / rel
        if not video.exists():
            raise InputError(f"{video}: missing video file for episode {idx}, camera {key!r}")
        vindex = self._index(video)
        times = vindex.times() - vindex.times()[0]
        fps = float(self.info["fps"])
        start_t = float(row[fields[2]])
        start = int(np.searchsorted(times, start_t - 0.5 / fps, side="left"))
        if length is None:
            end_t = row.get(f"videos/{key}/to_timestamp")
            if end_t is None:
                raise InputError(f"{self._episodes_file()}: episode {idx} has no field 'length'")
            length = int(np.searchsorted(times, float(end_t) - 0.5 / fps, side="left")) - start
        n = int(length)
        if n <= 0 or start + n > vindex.num_frames:
            raise InputError(
                f"{video}: episode {idx} spans frames {start}..{start + n - 1} "
                f"(field {fields[2]!r}={start_t}) but the file has {vindex.num_frames} frames"
            )
        return video, start, n

    def _episode_data(self, idx: int, row: dict[str, Any], columns: list[str]) -> dict[str, list]:
        """Columns of the data parquet restricted to one episode."""
        if self.version.startswith("v2"):
            rel = _format(
                self.info["data_path"],
                self.root / INFO,
                episode_chunk=idx // self.chunks_size,
                episode_index=idx,
            )
        else:
            for f in ("data/chunk_index", "data/file_index"):
                if row.get(f) is None:
                    raise InputError(f"{self._episodes_file()}: episode {idx} has no field {f!r}")
            rel = _format(
                self.info["data_path"],
                self.root / INFO,
                chunk_index=int(row["data/chunk_index"]),
                file_index=int(row["data/file_index"]),
            )
        path = self.root / rel
        if not path.exists():
            raise InputError(f"{path}: missing data file of episode {idx}")
        try:
            pq = _pq()
            schema_names = pq.read_schema(path).names
            missing = [c for c in columns if c not in schema_names]
            if missing:
                raise InputError(f"{path}: no column {missing[0]!r}")
            wanted = list(columns) + (["episode_index"] if "episode_index" in schema_names else [])
            data = pq.read_table(path, columns=wanted).to_pydict()
        except InputError:
            raise
        except Exception as exc:  # pyarrow raises many types for damaged files
            raise InputError(f"{path}: unreadable parquet ({exc.__class__.__name__})") from exc
        if "episode_index" in data:
            keep = [i for i, e in enumerate(data["episode_index"]) if int(e) == idx]
            data = {k: [v[i] for i in keep] for k, v in data.items()}
        if not data.get(columns[0]):
            raise InputError(f"{path}: no rows for episode {idx}")
        return data

    def _decode_image(self, cell: Any, position: int) -> np.ndarray:
        raw = cell.get("bytes") if isinstance(cell, dict) else cell
        if not isinstance(raw, bytes | bytearray):
            raise InputError(
                f"{self.root}: column {self.camera!r} row {position} holds no image bytes"
            )
        try:
            with Image.open(io.BytesIO(raw)) as img:
                return to_rgb_array(img)
        except (UnidentifiedImageError, OSError) as exc:
            raise InputError(
                f"{self.root}: column {self.camera!r} row {position}: undecodable image"
            ) from exc

    def _task_text(self, idx: int, row: dict[str, Any]) -> str:
        tasks = row.get("tasks")
        if isinstance(tasks, str):
            tasks = [tasks]
        if tasks:
            return "; ".join(str(t) for t in tasks if t)
        # fall back to task_index of the episode's first frame
        try:
            data = self._episode_data(idx, row, columns=["task_index"])
        except InputError:
            return ""
        return self._task_table().get(int(data["task_index"][0]), "")

    def _task_table(self) -> dict[int, str]:
        if self._tasks is None:
            self._tasks = {}
            if (self.root / TASKS_V2).exists():
                for r in _read_jsonl(self.root / TASKS_V2):
                    if "task_index" in r and "task" in r:
                        self._tasks[int(r["task_index"])] = str(r["task"])
            elif (self.root / TASKS_V3).exists():
                for r in _read_parquet_rows(self.root / TASKS_V3):
                    text = r.get("task", r.get("__index_level_0__"))
                    if "task_index" in r and text is not None:
                        self._tasks[int(r["task_index"])] = str(text)
        return self._tasks


def _read_json(path: Path, what: str) -> dict[str, Any]:
    if not path.exists():
        raise InputError(f"{path}: missing ({path.parent.parent} is not a {what})")
    try:
        data = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: invalid JSON ({exc})") from exc
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a JSON object")
    return data


def _read_jsonl(path: Path) -> list[dict[str, Any]]:
    if not path.exists():
        raise InputError(f"{path}: missing (needed to list the episodes)")
    rows = []
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        if not line.strip():
            continue
        try:
            row = json.loads(line)
        except json.JSONDecodeError as exc:
            raise InputError(f"{path}: line {n} is not valid JSON ({exc.msg})") from exc
        if not isinstance(row, dict):
            raise InputError(f"{path}: line {n} is not a JSON object")
        rows.append(row)
    return rows


def _read_parquet_rows(path: Path, skip_prefix: str | None = None) -> list[dict[str, Any]]:
    try:
        pq = _pq()
        names = pq.read_schema(path).names
        cols = [c for c in names if not (skip_prefix and c.startswith(skip_prefix))]
        return pq.read_table(path, columns=cols).to_pylist()
    except Exception as exc:  # ArrowInvalid, OSError, ...
        raise InputError(f"{path}: unreadable parquet ({exc.__class__.__name__}: {exc})") from exc


def _format(template: str, where: Path, **values: Any) -> str:
    try:
        return template.format(**values)
    except (KeyError, IndexError, ValueError) as exc:
        raise InputError(f"{where}: path template {template!r} has unknown field {exc}") from exc
