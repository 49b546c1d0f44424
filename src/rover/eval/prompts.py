"""Prompt templates for the LLM judge and QA answerer, stored as text files.

A template file has a `[system]` section and a `[user]` section; `{name}` placeholders are
filled with `str.format`, so literal braces in a template must be doubled.
"""

from __future__ import annotations

from functools import cache
from importlib import resources

from rover.vlm.types import Message, Prompt, PromptMeta


@cache
def load_template(name: str) -> tuple[str, str]:
    """(system text, user text) of `prompts/<name>.txt`."""
    text = resources.files("rover.eval").joinpath("prompts", f"{name}.txt").read_text()
    _, _, rest = text.partition("[system]")
    system, _, user = rest.partition("[user]")
    return system.strip(), user.strip()


def build_prompt(name: str, meta: PromptMeta, **fields: object) -> Prompt:
    """A two-message text prompt from a template filled with `fields`."""
    system, user = load_template(name)
    return Prompt(
        messages=[
            Message(role="system", content=system.format(**fields)),
            Message(role="user", content=user.format(**fields)),
        ],
        meta=meta,
    )
