"""Fixtures for method tests: a scripted VLM that records every prompt it is shown."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from rover.vlm.types import Completion, Prompt, SamplingParams, Usage


class ScriptedVLM:
    """A VLM whose answers come from a Python function of the prompt (no pixels read)."""

    backend = "scripted"
    model = "script"

    def __init__(self, script: Callable[[Prompt], str]) -> None:
        self.script = script
        self.prompts: list[Prompt] = []
        self.bound_to: list[str] = []

    def bind(self, episode) -> ScriptedVLM:
        self.bound_to.append(episode.id)
        return self

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        self.prompts.append(prompt)
        text = self.script(prompt)
        usage = Usage(prompt_tokens=10 * len(prompt.images()) + 5, completion_tokens=3)
        return Completion(text=text, usage=usage, backend=self.backend, model=self.model)

    def steps(self, kind: str = "rover.step") -> list[Prompt]:
        return [p for p in self.prompts if p.meta.kind == kind]


@pytest.fixture
def scripted():
    """Factory: ScriptedVLM(script)."""
    return ScriptedVLM
