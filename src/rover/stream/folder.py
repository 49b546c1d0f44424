"""Following a folder a camera process writes frames into (what `rover watch` reads).

Frames are image files (PNG, JPEG, ...) taken in file-name order, numbers compared as
numbers (`frame_9` before `frame_10`). A file is taken only when it is complete: its size
and modification time unchanged since the previous look, and it decodes in full; a
writer that writes in place is therefore never read half-way, and one that writes to a
hidden or temporary name and renames into place (the safest way) is read at once. Hidden
files (".name") and other suffixes are ignored; a file that appears with a name sorting
before one already taken is ignored (frames only go forward) and counted in `skipped`.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from rover.errors import InputError
from rover.io.frames import to_rgb_array
from rover.io.source import IMAGE_SUFFIXES

_NUMBER = re.compile(r"(\d+)")
# a file that stays undecodable this many looks after it stopped changing is corrupt
CORRUPT_AFTER = 20


def name_key(name: str) -> tuple:
    """Sort key: numbers in the name compare as numbers."""
    return tuple(int(p) if p.isdigit() else p for p in _NUMBER.split(name))


@dataclass
class Frame:
    path: Path
    index: int  # the last number in the file name, else the frame's position
    pixels: np.ndarray


@dataclass
class FolderFrames:
    """New complete frames of one folder, in order, each returned once by `poll`."""

    folder: Path
    taken: int = 0
    skipped: list[str] = field(default_factory=list)  # late or corrupt files, by name
    _last_key: tuple | None = None
    _last_index: int = -1
    _seen: dict[str, tuple[int, int]] = field(default_factory=dict)  # name -> (size, mtime)
    _bad: dict[str, int] = field(default_factory=dict)  # name -> undecodable looks
    _taken_ns: int = 0  # wall clock when the last frame was taken

    def __post_init__(self) -> None:
        self.folder = Path(self.folder)
        if not self.folder.is_dir():
            raise InputError(f"{self.folder}: not a folder")

    def poll(self) -> list[Frame]:
        """Complete frames that appeared since the last call (stops at the first one not
        complete yet, so frames are never taken out of order)."""
        out: list[Frame] = []
        for path in self._candidates():
            stat = self._stable(path)
            if stat is None:
                break  # still being written (or just appeared): look again next time
            pixels = _decode(path)
            if pixels is None:
                self._bad[path.name] = self._bad.get(path.name, 0) + 1
                if self._bad[path.name] < CORRUPT_AFTER:
                    break
                self._take(path)  # undecodable for good: skip it, keep following
                self.skipped.append(path.name)
                continue
            out.append(Frame(path, self._index(path), pixels))
            self._take(path)
        return out

    def _candidates(self) -> list[Path]:
        files = []
        for p in self.folder.iterdir():
            if p.name.startswith(".") or p.suffix.lower() not in IMAGE_SUFFIXES:
                continue
            key = name_key(p.name)
            if self._last_key is not None and key <= self._last_key:
                if key < self._last_key and p.name not in self.skipped and self._late(p):
                    self.skipped.append(p.name)  # arrived after later frames were taken
                continue
            files.append((key, p))
        return [p for _, p in sorted(files, key=lambda kp: kp[0])]

    def _stable(self, path: Path) -> tuple[int, int] | None:
        try:
            st = path.stat()
        except FileNotFoundError:  # renamed away between listing and looking
            return None
        now = (st.st_size, st.st_mtime_ns)
        before = self._seen.get(path.name)
        self._seen[path.name] = now
        return now if before == now and st.st_size > 0 else None

    def _index(self, path: Path) -> int:
        numbers = _NUMBER.findall(path.stem)
        index = int(numbers[-1]) if numbers else self._last_index + 1
        if index <= self._last_index:  # names without increasing numbers: count them
            index = self._last_index + 1
        self._last_index = index
        return index

    def _late(self, path: Path) -> bool:
        """Written after the last frame was taken (frames taken earlier were older)."""
        try:
            return path.stat().st_mtime_ns > self._taken_ns
        except FileNotFoundError:
            return False

    def _take(self, path: Path) -> None:
        self._taken_ns = time.time_ns()
        self._last_key = name_key(path.name)
        self._seen.pop(path.name, None)
        self._bad.pop(path.name, None)
        self.taken += 1


def _decode(path: Path) -> np.ndarray | None:
    try:
        with Image.open(path) as img:
            img.load()  # the whole file: a truncated one raises here
            return to_rgb_array(img)
    except (UnidentifiedImageError, OSError, ValueError):
        return None
