"""Completion budgets: how many tokens each call may answer with, sized to what it asks.

A fixed `max_tokens` either wastes budget on one-frame answers or cuts multi-frame ones:
a GVL or VideoConcat reply holds one block per frame (about 40 tokens each, "Frame k:",
a one-sentence description, the percentage), so 30 frames need ~1,200 tokens and 240
frames ~10,000, where a 512-token limit silently lost most of them. Every call therefore
asks for `frames x tokens_per_frame + overhead`, at least the backend's floor and at most
its cap. Gemini 2.5 models spend output tokens on thinking, hence its higher floor.

Overrides: a method's `max_tokens` / `tokens_per_frame` parameters, or an explicit
`--max-tokens` on the backend (then every call gets exactly that).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

TOKENS_PER_FRAME = 60  # a frame block is ~40 tokens; the rest is margin for longer prose
OVERHEAD = 64  # chatter before/after the blocks
FLOORS = {"gemini": 2048}  # thinking models count thoughts as output
CAPS = {"openai": 16384, "gemini": 8192, "hf": 4096}
DEFAULT_FLOOR = 512
DEFAULT_CAP = 32768


@dataclass(frozen=True)
class Budget:
    """The per-call completion budget rule for one method run."""

    backend: str = ""
    tokens_per_frame: int = TOKENS_PER_FRAME
    fixed: int | None = None  # every call gets exactly this (user override)

    def tokens(self, frames: int) -> int:
        """Tokens for a reply that answers `frames` frames."""
        if self.fixed is not None:
            return self.fixed
        floor = FLOORS.get(self.backend, DEFAULT_FLOOR)
        cap = CAPS.get(self.backend, DEFAULT_CAP)
        want = max(1, frames) * self.tokens_per_frame + OVERHEAD
        return int(min(max(want, floor), cap))


def budget_for(vlm: Any, max_tokens: int | None = None, tokens_per_frame: int | None = None):
    """The rule for `vlm`: a method's own override, else the backend's explicit setting."""
    fixed = max_tokens
    config = getattr(vlm, "config", None)
    if fixed is None and config is not None and "max_tokens" in config.model_fields_set:
        fixed = int(config.max_tokens)  # the user passed --max-tokens
    backend = str(getattr(vlm, "backend", ""))
    return Budget(backend, int(tokens_per_frame or TOKENS_PER_FRAME), fixed)
