"""Fixtures for method tests: a scripted VLM that records every prompt it is shown.

Like a real model it stops at `max_tokens` (a word counts as a token): a longer answer
is cut and reported with finish reason "length".
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from rover.vlm.testing import cut_words
from rover.vlm.types import Completion, Prompt, SamplingParams, Usage


class ScriptedVLM:
    """A VLM whose answers come from a Python function of the prompt (no pixels read)."""

    backend = "scripted"
    model = "script"

    def __init__(self, script: Callable[[Prompt], str]) -> None:
        self.script = script
        self.prompts: list[Prompt] = []
        self.params: list[SamplingParams] = []
        self.bound_to: list[str] = []

    def bind(self, episode) -> ScriptedVLM:
        self.bound_to.append(episode.id)
        return self

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        params = params or SamplingParams()
        self.prompts.append(prompt)
        self.params.append(params)
        text, cut = cut_words(self.script(prompt), params.max_tokens)
        usage = Usage(
            prompt_tokens=10 * len(prompt.images()) + 5, completion_tokens=len(text.split())
        )
        return Completion(
            text=text,
            usage=usage,
            backend=self.backend,
            model=self.model,
            finish_reason="length" if cut else "stop",
            truncated=cut,
        )

    def steps(self, kind: str = "rover.step") -> list[Prompt]:
        return [p for p in self.prompts if p.meta.kind == kind]


@pytest.fixture
def scripted():
    """Factory: ScriptedVLM(script)."""
    return ScriptedVLM
