"""The dataset directory: how generated (or converted) episodes are stored.

Layout (schema version 1)::

    DIR/dataset.json                  # DatasetInfo: name, version, views, generator config
    DIR/episodes/<id>/episode.json    # Episode metadata + ground truth (no pixels)
    DIR/episodes/<id>/<view>.mp4      # one H.264 video per view

An episode folder appears under its final name only once complete (written as
`<id>.part` then renamed), so a killed writer never leaves a half episode that a
reader would mistake for a finished one; resuming simply redoes `.part` folders.

Episode ids and view names are names, never paths: each is checked (`rover.paths`) and
every file is resolved inside the dataset root, so a hostile `episode.json` cannot make
rover read (and send to a VLM) a video from elsewhere on the disk.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field, ValidationError

from rover import __version__
from rover.episode import SCHEMA_VERSION, Episode
from rover.errors import InputError
from rover.io.video import read_video, write_video
from rover.paths import check_name, inside

DATASET_FILE = "dataset.json"
EPISODE_FILE = "episode.json"


class DatasetInfo(BaseModel):
    """Top-level description of a dataset directory."""

    schema_version: int = SCHEMA_VERSION
    name: str = "rover-dataset"
    rover_version: str = __version__
    views: list[str] = Field(default_factory=list)
    generator: dict[str, Any] = Field(default_factory=dict)  # config that produced it


def write_dataset_info(root: Path, info: DatasetInfo) -> None:
    root.mkdir(parents=True, exist_ok=True)
    _atomic_write_text(root / DATASET_FILE, info.model_dump_json(indent=2))


def read_dataset_info(root: Path) -> DatasetInfo:
    path = Path(root) / DATASET_FILE
    if not path.exists():
        raise InputError(f"{root}: not a rover dataset directory (no {DATASET_FILE})")
    try:
        info = DatasetInfo.model_validate_json(path.read_bytes())
    except ValidationError as exc:
        raise InputError(f"{path}: invalid dataset file ({_first_error(exc)})") from exc
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror or exc})") from exc
    for name in info.views:
        check_name(name, f"{path}: view name")
    if info.schema_version > SCHEMA_VERSION:
        raise InputError(
            f"{path}: schema version {info.schema_version} is newer than this rover "
            f"understands ({SCHEMA_VERSION}); upgrade rover"
        )
    return info


def episode_ids(root: Path) -> list[str]:
    """Ids of the complete episodes in a dataset directory, sorted."""
    ep_dir = Path(root) / "episodes"
    if not ep_dir.is_dir():
        return []
    return sorted(
        p.name
        for p in ep_dir.iterdir()
        if p.is_dir() and (p / EPISODE_FILE).exists() and not p.name.endswith(".part")
    )


def write_episode(root: Path, episode: Episode, fps: float | None = None) -> Path:
    """Write one episode (metadata + one MP4 per loaded view) atomically."""
    check_name(episode.id, "episode id")
    for name in [*episode.view_names, *episode.views]:
        check_name(name, f"episode {episode.id!r}: view name")
    ep_root = Path(root) / "episodes"
    final = ep_root / episode.id
    tmp = ep_root / (episode.id + ".part")
    if tmp.exists():
        shutil.rmtree(tmp)
    tmp.mkdir(parents=True)
    for name, frames in episode.views.items():
        write_video(tmp / f"{name}.mp4", frames, fps=fps or episode.fps)
    (tmp / EPISODE_FILE).write_text(episode.model_dump_json(indent=1))
    if final.exists():
        shutil.rmtree(final)
    tmp.rename(final)
    return final


def read_episode(
    root: Path, episode_id: str, views: list[str] | None = None, load_frames: bool = True
) -> Episode:
    """Load one episode; `views=None` loads every view, `load_frames=False` none."""
    check_name(episode_id, "episode id")
    folder = Path(root) / "episodes" / episode_id
    meta_path = folder / EPISODE_FILE
    if not meta_path.exists():
        raise InputError(f"{folder}: no {EPISODE_FILE} (unknown or unfinished episode)")
    meta_path = inside(root, "episodes", episode_id, EPISODE_FILE, what="episode file")
    try:
        raw = json.loads(meta_path.read_text(encoding="utf-8"))
        if not isinstance(raw, dict):
            raise ValueError("not a JSON object")
        raw.pop("views", None)
        episode = Episode.model_validate(raw)
    except (ValidationError, ValueError) as exc:  # JSON and UTF-8 errors are ValueErrors
        detail = _first_error(exc) if isinstance(exc, ValidationError) else str(exc)[:200]
        raise InputError(f"{meta_path}: invalid episode file ({detail})") from exc
    check_name(episode.id, f"{meta_path}: episode id")
    for name in episode.view_names:
        check_name(name, f"{meta_path}: view name")
    if not load_frames:
        return episode
    wanted = episode.view_names if views is None else views
    for v in wanted:
        if v not in episode.view_names:
            raise InputError(
                f"episode {episode_id!r} has no view {v!r}; views: {', '.join(episode.view_names)}"
            )
    loaded = {
        v: read_video(inside(root, "episodes", episode_id, f"{v}.mp4", what="video"))
        for v in wanted
    }
    for v, arr in loaded.items():
        if len(arr) != episode.num_frames:
            raise InputError(
                f"{folder / (v + '.mp4')}: {len(arr)} frames but episode.json lists "
                f"{episode.num_frames}"
            )
    return episode.model_copy(update={"views": loaded})


def load_dataset(
    root: Path, views: list[str] | None = None, load_frames: bool = True
) -> list[Episode]:
    read_dataset_info(root)
    return [read_episode(root, i, views, load_frames) for i in episode_ids(root)]


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def _first_error(exc: ValidationError) -> str:
    err = exc.errors()[0]
    loc = ".".join(str(x) for x in err.get("loc", ()))
    return f"{loc}: {err.get('msg')}" if loc else str(err.get("msg"))
