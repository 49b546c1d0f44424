"""One way in for every video or dataset: spec strings, the reader interface, helpers.

A *spec* names where episodes come from. It is a path, optionally with a prefix and
query options::

    clip.mp4                      a video file (MP4/MOV/MKV/WebM/AVI)
    frames/                       a folder of numbered images
    DIR  or  DIR/episodes/<id>    a rover dataset directory (or one of its episodes)
    lerobot:PATH?camera=observation.images.top
    rlds:PATH?camera=image        OpenX RLDS TFRecords (no TensorFlow needed)
    hdf5:demo.hdf5?camera=agentview
    ...?episode=<id>              pick one episode from a multi-episode source

Without a prefix the kind is guessed from what is on disk. Every reader returns
`Episode`s holding only the frames asked for, so callers never pay for decoding a
whole video they will subsample anyway.
"""

from __future__ import annotations

import importlib
from abc import ABC, abstractmethod
from collections.abc import Iterator
from pathlib import Path
from typing import Any
from urllib.parse import parse_qsl

import numpy as np

from rover.episode import Episode, GroundTruth
from rover.errors import InputError

VIDEO_SUFFIXES = {".mp4", ".mov", ".mkv", ".webm", ".avi", ".m4v"}
IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".webp", ".bmp"}
HDF5_SUFFIXES = {".hdf5", ".h5", ".he5"}

# spec prefix -> "module:Class" (imported lazily, so a reader's dependencies load only when used)
SOURCE_KINDS: dict[str, str] = {
    "video": "rover.io.plain:VideoFileSource",
    "frames": "rover.io.plain:FrameFolderSource",
    "dataset": "rover.io.plain:DatasetDirSource",
    "lerobot": "rover.io.lerobot:LeRobotSource",
    "rlds": "rover.io.rlds:RLDSSource",
    "hdf5": "rover.io.hdf5:HDF5Source",
}


class Default:
    """Marker for "use the reader's default" where None already means "all" / "full size"."""

    def __repr__(self) -> str:
        return "DEFAULT"


DEFAULT = Default()

# query keys every reader understands; `camera` is an alias of `view`
COMMON_KEYS = {"view", "camera", "episode", "task", "fps"}


class SourceReader(ABC):
    """A collection of episodes; `read` returns one Episode holding the frames asked for.

    Subclasses set `kind` and implement `episode_ids` and `_read`; defaults given to
    `open_source` (task, view, frames, size) apply to `read` calls that leave them out.
    """

    kind: str = ""
    #: query options this reader accepts besides COMMON_KEYS
    extra_keys: frozenset[str] = frozenset()

    def __init__(
        self,
        path: Path,
        *,
        view: str | None = None,
        task: str | None = None,
        frames: int | None = None,
        size: int | None = 256,
        fps: float | None = None,
        episode: str | None = None,
        options: dict[str, str] | None = None,
    ) -> None:
        self.path = Path(path)
        self.view = view
        self.task = task
        self.frames = frames
        self.size = size
        self.fps = fps
        self.only_episode = episode
        self.options = dict(options or {})
        unknown = set(self.options) - set(self.extra_keys)
        if unknown:
            valid = sorted(COMMON_KEYS | set(self.extra_keys))
            raise InputError(
                f"{self.path}: unknown option {sorted(unknown)[0]!r} for {self.kind} sources; "
                f"valid: {', '.join(valid)}"
            )

    @property
    def name(self) -> str:
        """Short human-readable name of the source (used in reports and episode.source)."""
        return f"{self.kind}:{self.path}"

    @property
    def dataset(self) -> str:
        """Name of the dataset this source holds, for per-dataset tables and run ids.

        Readers whose folders carry a builder or dataset name (RLDS `dataset_info.json`,
        a version folder's parent) override this; the default is the file stem or folder
        name.
        """
        path = self.path if self.path.name not in ("", ".") else self.path.resolve()
        return (path.stem if path.is_file() else path.name) or "source"

    def task_of(self, episode_id: str) -> str:
        """The task text an episode will carry, read as cheaply as the format allows.

        Used to refuse a run before any VLM call when episodes have no task. The
        default reads one frame; readers that keep tasks in metadata override it.
        """
        if self.task is not None:
            return self.task
        return self._read(episode_id, 1).task

    def episode_ids(self) -> list[str]:
        """Ids of the episodes this source holds, in a stable order."""
        ids = self._episode_ids()
        if self.only_episode is not None:
            if self.only_episode not in ids:
                shown = ", ".join(ids[:5]) + (" ..." if len(ids) > 5 else "")
                raise InputError(
                    f"{self.path}: no episode {self.only_episode!r}; episodes: {shown or 'none'}"
                )
            return [self.only_episode]
        return ids

    def read(
        self,
        episode_id: str,
        frames: int | None | Default = DEFAULT,
        size: int | None | Default = DEFAULT,
    ) -> Episode:
        """One episode with `frames` evenly sampled frames, long side at most `size` px.

        Left out, `frames`/`size` take the reader's defaults; `None` means all frames /
        original size.
        """
        n = self.frames if isinstance(frames, Default) else frames
        if n is not None and n <= 0:
            raise InputError(f"frames must be positive, got {n}")
        s = self.size if isinstance(size, Default) else size
        episode = self._read(episode_id, n)
        if self.task is not None:
            episode = episode.model_copy(update={"task": self.task})
        return episode.resized(s)

    def __iter__(self) -> Iterator[Episode]:
        for episode_id in self.episode_ids():
            yield self.read(episode_id)

    def __len__(self) -> int:
        return len(self.episode_ids())

    @abstractmethod
    def _episode_ids(self) -> list[str]: ...

    @abstractmethod
    def _read(self, episode_id: str, frames: int | None) -> Episode: ...


def parse_spec(spec: str | Path) -> tuple[str | None, Path, dict[str, str]]:
    """Split a spec into (kind or None when to be guessed, path, query options)."""
    text = str(spec)
    kind: str | None = None
    head, sep, rest = text.partition(":")
    if sep and head.isalnum() and len(head) > 1 and not Path(text).exists():
        if head.lower() not in SOURCE_KINDS:
            raise InputError(
                f"unknown source prefix {head + ':'!r} in {text!r}; valid prefixes: "
                + ", ".join(f"{k}:" for k in SOURCE_KINDS)
            )
        kind, text = head.lower(), rest
    params: dict[str, str] = {}
    if "?" in text and not Path(text).exists():
        text, _, query = text.partition("?")
        params = dict(parse_qsl(query, keep_blank_values=True))
    if not text:
        raise InputError(f"source spec {str(spec)!r} has no path")
    return kind, Path(text).expanduser(), params


def guess_kind(path: Path) -> str:
    """The source kind for an unprefixed path, from what is on disk."""
    if not path.exists():
        raise InputError(f"{path}: no such file or directory")
    if path.is_file():
        suffix = path.suffix.lower()
        if suffix in VIDEO_SUFFIXES:
            return "video"
        if suffix in HDF5_SUFFIXES:
            return "hdf5"
        if ".tfrecord" in path.name:
            return "rlds"
        raise InputError(
            f"{path}: unsupported file type {suffix or '(none)'!r}; expected a video "
            f"({', '.join(sorted(VIDEO_SUFFIXES))}), an HDF5 file or a folder"
        )
    if (path / "dataset.json").exists() or (path / "episode.json").exists():
        return "dataset"
    if (path / "meta" / "info.json").exists():
        return "lerobot"
    if (path / "features.json").exists() or any(path.glob("*.tfrecord*")):
        return "rlds"
    return "frames"


def open_source(spec: str | Path, **opts: Any) -> SourceReader:
    """Open any supported source by spec string (see module docstring).

    Keyword options (`view`, `task`, `frames`, `size`, `fps`, `episode`, plus
    reader-specific ones) override the same keys given in the spec's query.
    """
    kind, path, params = parse_spec(spec)
    kind = kind or guess_kind(path)
    if not path.exists():
        raise InputError(f"{path}: no such file or directory")
    merged: dict[str, Any] = dict(params)
    merged.update({k: v for k, v in opts.items() if v is not None})
    if "camera" in merged:
        merged.setdefault("view", merged.pop("camera"))
        merged.pop("camera", None)
    kwargs = {
        k: merged.pop(k)
        for k in ("view", "task", "frames", "size", "fps", "episode")
        if k in merged
    }
    for key in ("frames", "size"):
        if key in kwargs and kwargs[key] is not None:
            kwargs[key] = _as_int(kwargs[key], key, spec)
    if "fps" in kwargs:
        kwargs["fps"] = _as_float(kwargs["fps"], "fps", spec)
    cls = _reader_class(kind)
    return cls(path, options={k: str(v) for k, v in merged.items()}, **kwargs)


def load_episode(
    spec_or_path: str | Path,
    *,
    frames: int | None = None,
    size: int | None = 256,
    task: str | None = None,
    view: str | None = None,
) -> Episode:
    """Load exactly one episode from a spec; errors if the source holds several.

    `frames=N` samples N frames evenly (first and last kept) and records their original
    indices; `size` bounds the long side (never upscales). Sources without ground truth
    come back without it: see `with_frame_number_truth` for the App. L convention.
    """
    reader = open_source(spec_or_path, task=task, view=view)
    ids = reader.episode_ids()
    if not ids:
        raise InputError(f"{reader.path}: no episodes found")
    if len(ids) > 1:
        shown = ", ".join(ids[:3]) + (" ..." if len(ids) > 3 else "")
        raise InputError(
            f"{reader.path}: holds {len(ids)} episodes ({shown}); pick one with "
            f"'?episode=<id>'" + (" or DIR/episodes/<id>" if reader.kind == "dataset" else "")
        )
    return reader.read(ids[0], frames=frames, size=size)


def with_frame_number_truth(episode: Episode, total_frames: int | None = None) -> Episode:
    """Frame number as ground-truth progress (App. L): index / (total - 1).

    Real videos have no measured progress, so the paper (after GVL) scores predictions
    against normalised time. `total_frames` defaults to the recording length the source
    stored in `episode.extra["total_frames"]` (else the last index + 1); frame folders
    whose numbering starts above zero are normalised over their own first..last number.
    """
    first = 0
    if total_frames is None:
        if "index_range" in episode.extra:
            first, last = episode.extra["index_range"]
            total_frames = last - first + 1
        elif "total_frames" in episode.extra:
            total_frames = int(episode.extra["total_frames"])
        else:
            total_frames = max(episode.frame_indices) + 1
    if total_frames < 1:
        raise InputError(f"episode {episode.id!r}: total_frames must be positive")
    denom = max(total_frames - 1, 1)
    progress = [min(max((i - first) / denom, 0.0), 1.0) for i in episode.frame_indices]
    return episode.model_copy(
        update={"truth": GroundTruth(progress=progress, progress_source="frame_number")}
    )


def sample_episode_ids(reader: SourceReader, n: int | None, seed: int) -> list[str]:
    """n episode ids drawn without replacement, reproducibly for a seed, in source order.

    Sorting the draw back into source order keeps runs comparable: the same seed picks
    the same episodes whatever order they are later processed in.
    """
    ids = reader.episode_ids()
    if n is None or n >= len(ids):
        return list(ids)
    if n <= 0:
        raise InputError(f"--episodes must be positive, got {n}")
    rng = np.random.default_rng(seed)
    picked = sorted(int(i) for i in rng.choice(len(ids), size=n, replace=False))
    return [ids[i] for i in picked]


def require_tasks(reader: SourceReader, ids: list[str], where: str = "") -> None:
    """Refuse (one line) when an episode has no task text: every VLM call would ask about
    "the subtask of ." and be wasted. Checked before any call is made."""
    for episode_id in ids:
        if not reader.task_of(episode_id).strip():
            raise InputError(
                f"{where or reader.path}: episode {episode_id!r} carries no task description; "
                'pass --task "..." (or ?task=... in the spec)'
            )


def spec_with_options(spec: str, **options: str | None) -> str:
    """`spec` with query options added (`?task=...`), URL-quoted so any text survives."""
    from urllib.parse import urlencode

    extra = {k: v for k, v in options.items() if v is not None}
    if not extra:
        return spec
    kind, path, params = parse_spec(spec)
    params.update(extra)
    head = f"{kind}:" if kind else ""
    return f"{head}{path}?{urlencode(params)}"


def _reader_class(kind: str) -> type[SourceReader]:
    module_name, _, cls_name = SOURCE_KINDS[kind].partition(":")
    return getattr(importlib.import_module(module_name), cls_name)


def _as_int(value: Any, key: str, spec: Any) -> int:
    try:
        return int(value)
    except (TypeError, ValueError):
        raise InputError(f"{spec}: option {key!r} must be an integer, got {value!r}") from None


def _as_float(value: Any, key: str, spec: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise InputError(f"{spec}: option {key!r} must be a number, got {value!r}") from None
