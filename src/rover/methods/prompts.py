"""Prompt templates (text files under `prompts/`) and the small helpers that fill them.

Templates are plain text written from App. E of the paper. Placeholders are `{name}`;
only names passed to `render` are replaced, so the literal `{}` slots the paper's answer
formats show ("Frame description: {}") stay as they are, and braces inside a user's task
text can never break formatting.
"""

from __future__ import annotations

from functools import cache
from importlib import resources


@cache
def template(name: str) -> str:
    """The text of `prompts/<name>.txt` (read once per process)."""
    path = resources.files("rover.methods").joinpath("prompts", f"{name}.txt")
    return path.read_text(encoding="utf-8").rstrip("\n")


def render(name: str, **values: object) -> str:
    """Fill the named placeholders of a template; others are left untouched."""
    text = template(name)
    for key, value in values.items():
        text = text.replace("{" + key + "}", str(value))
    return text


def pct(value: float | None) -> str:
    """A progress value as the model would write it: integers without a trailing .0."""
    if value is None:
        return "unknown"
    return f"{value:.0f}" if float(value).is_integer() else f"{value:.1f}"
