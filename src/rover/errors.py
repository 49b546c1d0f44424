"""Errors a user can act on.

Anything raised as a `RoverError` is shown by the CLI as one line (no traceback) and
exits non-zero, so its message must name the problem and, where possible, the fix.
"""

from __future__ import annotations


class RoverError(Exception):
    """A problem with the user's input or environment, reported as one line."""

    exit_code: int = 2


class InputError(RoverError):
    """A file, video, dataset or option the user gave us is missing or malformed."""


class MissingExtraError(RoverError):
    """An optional dependency is not installed; the message says which extra to install."""

    def __init__(self, package: str, extra: str, purpose: str) -> None:
        super().__init__(
            f"{purpose} needs the '{package}' package: pip install 'rover-vlm[{extra}]'"
        )


class BackendError(RoverError):
    """A VLM backend failed in a way retrying will not fix (bad key, unknown model...)."""

    exit_code = 3
