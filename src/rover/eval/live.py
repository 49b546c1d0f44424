"""Live counting of VLM calls while a run works, for the progress display.

A method like ROVER makes ~40 sequential calls per episode; counting them only when a
unit finishes leaves the display at zero for minutes against a real API. `Counted`
wraps a backend so each finished call adds its tokens to the run's counters at once.
The wrapper forwards every other attribute (image encoding, name...) to the backend,
and binding it to an episode returns a wrapped bound backend.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class Counted:
    """A VLM whose every completed call is reported to `on_call(tokens)`."""

    def __init__(self, inner: Any, on_call: Callable[[int], None]) -> None:
        self._inner = inner
        self._on_call = on_call

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)

    def bind(self, episode: Any) -> Counted:
        return Counted(self._inner.bind(episode), self._on_call)

    async def complete(self, *args: Any, **kwargs: Any) -> Any:
        completion = await self._inner.complete(*args, **kwargs)
        usage = getattr(completion, "usage", None)
        self._on_call(int(getattr(usage, "total_tokens", 0) or 0))
        return completion
