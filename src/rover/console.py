"""The one output layer for the terminal: every command prints through these helpers.

Model replies, file names, method names, subtask paths and server error bodies are data,
not markup: a reply containing `[/]` once crashed Rich after every call of a run had been
paid for, `[link=…]` made clickable links, raw escape sequences retitled or cleared the
terminal, and `openai:m…` could turn into an emoji. So:

- `safe(text)` is text fit for a terminal: secrets scrubbed, escape sequences and control
  characters stripped (newlines and tabs kept).
- `esc(text)` is `safe` text escaped for a Rich markup string we write ourselves
  (`console.print(f"[bold]{esc(name)}[/]")`).
- `line(text)` is one scrubbed, stripped line, cut only after scrubbing.
- `make_console()` never guesses markup in data (no highlighting, no emoji codes).
- `print_error(message)` is the CLI's one-line `error: …`.
"""

from __future__ import annotations

from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.text import Text

from rover.vlm.scrub import scrub, scrub_line, strip_controls


def safe(text: Any) -> str:
    """`text` as a string with secrets scrubbed and terminal control sequences removed."""
    return strip_controls(scrub(str(text)))


def esc(text: Any) -> str:
    """`safe(text)` escaped for use inside a Rich markup string.

    As with Rich's own `escape`, a trailing backslash is doubled so that a tag after it
    still closes; at the very end of a line it shows as two.
    """
    return escape(safe(text))


def line(text: Any, limit: int | None = None) -> str:
    """One line of safe text (whitespace folded), cut to `limit` characters after scrubbing."""
    return scrub_line(str(text), limit)


def plain(text: Any, style: str = "") -> Text:
    """A Rich `Text` of safe text: rendered literally, whatever brackets it holds."""
    return Text(safe(text), style=style)


def make_console(stderr: bool = False, **kwargs: Any) -> Console:
    """A Console that renders only the markup we write: no highlighting, no emoji codes."""
    kwargs.setdefault("highlight", False)
    kwargs.setdefault("emoji", False)
    return Console(stderr=stderr, **kwargs)


def print_error(message: Any, console: Console | None = None) -> None:
    """`error: <message>` on one line of stderr, the message taken literally."""
    console = console or make_console(stderr=True)
    console.print(
        Text.assemble(("error:", "bold red"), " ", line(message)),
        soft_wrap=True,
    )
