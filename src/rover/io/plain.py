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
_SEPARATORS = re.compile(r"[_\-.\s]+")


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

    def task_of(self, episode_id: str) -> str:
        return self.task or ""

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
    """(frame number, path) for every image of a single-camera folder, ordered by number.

    The number is the last run of digits in the file name, so `frame_12.jpg` follows
    `frame_6.jpg` and gaps keep their original indices. A folder without numbers falls
    back to name order (index = position). A folder holding several cameras by file-name
    prefix is an error here; `camera_groups` splits those.
    """
    groups = camera_groups(folder)
    if len(groups) > 1:
        raise InputError(f"{folder}: holds several views ({', '.join(groups)}); pick one")
    return next(iter(groups.values()))


def camera_groups(folder: Path) -> dict[str, list[tuple[int, Path]]]:
    """Frames of a folder grouped into views by file-name prefix, each ordered by number.

    Robot logs write several cameras into one folder (`frame_wrist_0.jpg`,
    `frame_external_0.jpg`, ...): the text around a file's last number says which camera
    it is. Views are named by what tells their prefixes apart (`wrist`, `external`); a
    folder with one prefix is one view named "rgb".
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
    numbers = [list(_NUMBER.finditer(p.stem)) for p in files]
    if not any(numbers):
        return {FrameFolderSource.view_name: list(enumerate(files))}
    missing = [p for p, n in zip(files, numbers, strict=True) if not n]
    if missing:
        raise InputError(f"{missing[0]}: frame file name has no frame number")
    by_key: dict[tuple[str, str], dict[int, Path]] = {}
    for p, found in zip(files, numbers, strict=True):
        last = found[-1]
        key = (p.stem[: last.start()], p.stem[last.end() :])
        seen = by_key.setdefault(key, {})
        idx = int(last.group())
        if idx in seen:
            raise InputError(f"{p}: frame number {idx} also used by {seen[idx].name}")
        seen[idx] = p
    names = _view_labels(list(by_key))
    return {
        names[key]: sorted(items.items())
        for key, items in sorted(by_key.items(), key=lambda kv: names[kv[0]])
    }


def _view_labels(keys: list[tuple[str, str]]) -> dict[tuple[str, str], str]:
    """Short view names: the file-name words that differ between the prefixes."""
    if len(keys) == 1:
        return {keys[0]: FrameFolderSource.view_name}
    words = {k: [w for w in _SEPARATORS.split(k[0] + "_" + k[1]) if w] for k in keys}
    lead = 0
    while all(len(w) > lead for w in words.values()) and (
        len({w[lead] for w in words.values()}) == 1
    ):
        lead += 1
    trail = 0
    while all(len(w) > lead + trail for w in words.values()) and (
        len({w[-1 - trail] for w in words.values()}) == 1
    ):
        trail += 1
    labels = {k: "_".join(w[lead : len(w) - trail]) for k, w in words.items()}
    if any(not v for v in labels.values()) or len(set(labels.values())) < len(labels):
        labels = {k: "_".join(w) or "rgb" for k, w in words.items()}
    return labels


class FrameFolderSource(SourceReader):
    """A folder of images = one episode, id = folder name, index = number in file name.

    Several cameras in one folder (told apart by file-name prefix) are several views;
    `view` / `?camera=` picks one by its short name (`wrist`) or its prefix.
    """

    kind = "frames"
    view_name = "rgb"

    def _episode_ids(self) -> list[str]:
        groups = camera_groups(self.path)  # validates early
        if len(groups) > 1:
            self._pick(groups)
        return [self.path.resolve().name]

    def task_of(self, episode_id: str) -> str:
        return self.task or ""

    def _pick(self, groups: dict[str, list[tuple[int, Path]]]) -> str:
        names = list(groups)
        if self.view is None:
            return names[0]
        if len(names) == 1:
            return names[0]
        wanted = self.view.strip("_-. ").lower()
        for name, items in groups.items():
            stem = items[0][1].stem
            prefix = stem[: list(_NUMBER.finditer(stem))[-1].start()].strip("_-. ")
            if wanted in (name.lower(), prefix.lower()):
                return name
        raise InputError(f"{self.path}: no view {self.view!r}; views found: {', '.join(names)}")

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        groups = camera_groups(self.path)
        chosen_view = self._pick(groups)
        items = groups[chosen_view]
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
        if len(groups) == 1:
            name = self.view or self.view_name
            names = [name]
        else:
            name, names = chosen_view, list(groups)
        return Episode(
            id=episode_id,
            task=self.task or "",
            source=str(self.path),
            fps=self.fps or DEFAULT_FPS,
            frame_indices=[idx for idx, _ in chosen],
            view_names=names,
            default_view=name,
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

    @property
    def dataset(self) -> str:
        return read_dataset_info(self.root).name

    def task_of(self, episode_id: str) -> str:
        if self.task is not None:
            return self.task
        return read_episode(self.root, episode_id, load_frames=False).task

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
