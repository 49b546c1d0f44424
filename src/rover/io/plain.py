"""Plain sources: one video file, a folder of numbered frames, a rover dataset directory."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from rover.episode import Episode, even_positions
from rover.errors import InputError
from rover.io.dataset import EPISODE_FILE, episode_ids, read_dataset_info, read_episode
from rover.io.frames import to_rgb_array
from rover.io.seek import decode_frames, index_video
from rover.io.source import IMAGE_SUFFIXES, SourceReader
from rover.io.video import read_video

DEFAULT_FPS = 30.0
_NUMBER = re.compile(r"\d+")


def sample_positions(total: int, frames: int | None) -> list[int]:
    """Positions to keep out of `total`: all, or `frames` spread evenly (ends kept)."""
    if total <= 0:
        raise InputError("source has zero frames")
    return list(range(total)) if frames is None else even_positions(total, frames)


class VideoFileSource(SourceReader):
    """One video file (any container PyAV reads) = one episode, id = file stem."""

    kind = "video"
    view_name = "rgb"

    def _episode_ids(self) -> list[str]:
        if not self.path.is_file():
            raise InputError(f"{self.path}: not a video file")
        return [self.path.stem]

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        index = index_video(self.path)
        total, fps = index.num_frames, index.fps
        positions = sample_positions(total, frames)
        pixels = decode_frames(self.path, positions, index)
        name = self.view or self.view_name
        return Episode(
            id=episode_id,
            task=self.task or "",
            source=str(self.path),
            fps=self.fps or fps,
            frame_indices=positions,
            view_names=[name],
            views={name: pixels},
            extra={"total_frames": total},
        )


def numbered_images(folder: Path) -> list[tuple[int, Path]]:
    """(frame number, path) for every image in a folder, ordered by number.

    The number is the last run of digits in the file name, so `frame_12.jpg` follows
    `frame_6.jpg` and gaps keep their original indices. A folder without numbers falls
    back to name order (index = position).
    """
    if not folder.is_dir():
        raise InputError(f"{folder}: not a folder")
    files = sorted(
        p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES
    )
    if not files:
        raise InputError(
            f"{folder}: no frames found (expected {', '.join(sorted(IMAGE_SUFFIXES))} images)"
        )
    numbers = [_NUMBER.findall(p.stem) for p in files]
    if not any(numbers):
        return list(enumerate(files))
    missing = [p for p, n in zip(files, numbers, strict=True) if not n]
    if missing:
        raise InputError(f"{missing[0]}: frame file name has no frame number")
    seen: dict[int, Path] = {}
    for p, n in zip(files, numbers, strict=True):
        idx = int(n[-1])
        if idx in seen:
            raise InputError(f"{p}: frame number {idx} also used by {seen[idx].name}")
        seen[idx] = p
    return sorted(seen.items())


class FrameFolderSource(SourceReader):
    """A folder of images = one episode, id = folder name, index = number in file name."""

    kind = "frames"
    view_name = "rgb"

    def _episode_ids(self) -> list[str]:
        numbered_images(self.path)  # validates early
        return [self.path.resolve().name]

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        items = numbered_images(self.path)
        positions = sample_positions(len(items), frames)
        chosen = [items[p] for p in positions]
        arrays = [_load_image(path) for _, path in chosen]
        shape = arrays[0].shape
        for (_, path), arr in zip(chosen, arrays, strict=True):
            if arr.shape != shape:
                raise InputError(
                    f"{path}: frame size {arr.shape[1]}x{arr.shape[0]} differs from "
                    f"{shape[1]}x{shape[0]} of {chosen[0][1].name}"
                )
        name = self.view or self.view_name
        return Episode(
            id=episode_id,
            task=self.task or "",
            source=str(self.path),
            fps=self.fps or DEFAULT_FPS,
            frame_indices=[idx for idx, _ in chosen],
            view_names=[name],
            views={name: np.stack(arrays)},
            extra={"index_range": [items[0][0], items[-1][0]], "total_frames": len(items)},
        )


def _load_image(path: Path) -> np.ndarray:
    try:
        with Image.open(path) as img:
            return to_rgb_array(img)
    except (UnidentifiedImageError, OSError) as exc:
        raise InputError(f"{path}: unreadable image ({exc.__class__.__name__})") from exc


class DatasetDirSource(SourceReader):
    """A rover dataset directory (`DIR`) or one episode folder (`DIR/episodes/<id>`)."""

    kind = "dataset"

    def __init__(self, path: Path, **kwargs) -> None:
        super().__init__(path, **kwargs)
        if (self.path / EPISODE_FILE).exists():
            self.root = self.path.parent.parent
            self._single: str | None = self.path.name
        else:
            read_dataset_info(self.path)  # one-line error if this is not a dataset
            self.root = self.path
            self._single = None

    def _episode_ids(self) -> list[str]:
        return [self._single] if self._single else episode_ids(self.root)

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        meta = read_episode(self.root, episode_id, load_frames=False)
        views = meta.view_names if self.view is None else [self.view]
        for v in views:
            if v not in meta.view_names:
                raise InputError(
                    f"{self.root / 'episodes' / episode_id}: no view {v!r}; "
                    f"views: {', '.join(meta.view_names)}"
                )
        positions = sample_positions(meta.num_frames, frames)
        folder = self.root / "episodes" / episode_id
        loaded = {}
        for v in views:
            arr = read_video(folder / f"{v}.mp4", positions if frames is not None else None)
            if frames is None and len(arr) != meta.num_frames:
                raise InputError(
                    f"{folder / (v + '.mp4')}: {len(arr)} frames but {EPISODE_FILE} lists "
                    f"{meta.num_frames}"
                )
            loaded[v] = arr
        episode = meta.select(positions) if frames is not None else meta
        update: dict = {"views": loaded}
        if self.view is not None:
            update["default_view"] = self.view
        if self.fps is not None:
            update["fps"] = self.fps
        if not episode.source:
            update["source"] = str(folder)
        return episode.model_copy(update=update)
