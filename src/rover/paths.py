"""Paths rover is told about: names that must stay names, outputs checked before any work.

A dataset is untrusted input. Its episode ids and view names become file names, so a view
called `/home/me/secret` or `../../x` once made rover read that `.mp4`, send its frames to
a paid VLM and put them in a shareable report. `check_name` refuses anything that is not
a plain name, and `inside` resolves a file (symlinks included) and refuses it unless it
lies within its root.

Outputs are checked before the first VLM call or simulation step, not after: `--out`
being a directory, a file inside a file, or an unwritable place is found in milliseconds
(`check_output_file`, `check_output_dir`).
"""

from __future__ import annotations

import os
from pathlib import Path

from rover.errors import InputError

_MAX_NAME = 255


def check_name(value: object, what: str) -> str:
    """`value` if it is a plain file-name component; else InputError naming `what`.

    A name is non-empty, at most 255 characters, has no path separator, NUL or other
    control character, and is not `.` or `..`.
    """
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"{what} must be a non-empty name, got {value!r}")
    bad = (
        "/" in value
        or "\\" in value
        or value in (".", "..")
        or any(ord(c) < 32 or ord(c) == 127 for c in value)
        or len(value) > _MAX_NAME
    )
    if bad:
        shown = value if len(value) <= 80 else value[:80] + "…"
        raise InputError(
            f"{what} {shown!r} is not a plain name (no '/', '\\', '..', control characters)"
        )
    return value


def inside(root: Path, *parts: str, what: str = "file") -> Path:
    """`root/parts...` resolved (symlinks followed); InputError if it leaves `root`."""
    base = Path(root).resolve()
    path = base.joinpath(*parts).resolve()
    if path != base and base not in path.parents:
        raise InputError(f"{what} {Path(*parts)} resolves outside {root} (to {path}); refused")
    return path


def check_output_file(path: Path, what: str = "--out") -> Path:
    """Refuse an output file path that cannot be written, before any work is done.

    The path may exist (it is replaced) but must not be a directory; its parent must be a
    directory we can write to, or creatable.
    """
    path = Path(path).expanduser()
    if path.is_dir():
        raise InputError(f"{what} {path} is a directory; give a file path")
    parent = _existing_parent(path.parent)
    if not parent.is_dir():
        raise InputError(f"{what} {path}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{what} {path}: cannot write in {parent} (permission denied)")
    if path.exists() and not os.access(path, os.W_OK):
        raise InputError(f"{what} {path}: the file exists and is not writable")
    return path


def check_output_dir(
    path: Path, what: str = "--out", marker: str | None = None, allow_nonempty: bool = False
) -> Path:
    """Refuse an output directory rover should not write into, before any work is done.

    Args:
        path: the directory (created later by the caller).
        what: the option that named it, for the message.
        marker: a file that identifies a directory rover made itself (`dataset.json`,
            `run.json`); a non-empty directory without it is somebody else's.
        allow_nonempty: accept any non-empty directory (the caller knows better).
    """
    path = Path(path).expanduser()
    if path.exists() and not path.is_dir():
        raise InputError(f"{what} {path} exists and is not a directory")
    parent = _existing_parent(path)
    if not parent.is_dir():
        raise InputError(f"{what} {path}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{what} {path}: cannot write in {parent} (permission denied)")
    if path.is_dir() and not allow_nonempty and any(path.iterdir()):
        if marker is None or not (path / marker).exists():
            raise InputError(
                f"{what} {path} is a non-empty folder rover did not make; "
                "choose a new or empty folder"
            )
    return path


def _existing_parent(path: Path) -> Path:
    """The nearest existing ancestor of `path` (itself if it exists)."""
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path
