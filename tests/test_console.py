"""Model and user text reach the terminal as text: no markup, no escapes, no emoji, no keys."""

from __future__ import annotations

import io

import pytest
from rich.console import Console

from rover.console import esc, line, make_console, plain, print_error, safe
from rover.vlm.scrub import register_secret

HOSTILE = [
    "[/]",
    "[/bold] closes nothing",
    "[link=http://evil.example]click me[/link]",
    "[bold red]shouting[/]",
    "a path with [/ in it",
    "openai:m:smile: and :cross_mark:",
    "trailing backslash \\",
]


def _render(markup: str) -> str:
    out = io.StringIO()
    Console(file=out, width=200, color_system=None, emoji=False).print(markup)
    return out.getvalue().rstrip("\n")


@pytest.mark.parametrize("text", HOSTILE)
def test_escaped_text_renders_as_itself(text):
    assert _render(f"[bold]{esc(text)}[/bold]") == text


@pytest.mark.parametrize("text", HOSTILE[:-1])  # a trailing backslash is doubled (Rich)
def test_plain_text_and_the_console_print_literally(text):
    out = io.StringIO()
    console = make_console(file=out, width=200, color_system=None)
    console.print(plain(text))
    console.print(f"x {esc(text)}")
    assert out.getvalue().splitlines() == [text, f"x {text}"]


def test_terminal_escape_sequences_never_pass():
    hostile = "title\x1b]0;pwned\x07 clear\x1b[2J colour\x1b[31m bell\x07 nul\x00 c1\x9b"
    for shown in (safe(hostile), esc(hostile), line(hostile)):
        assert "\x1b" not in shown and "\x07" not in shown and "\x00" not in shown
        assert "\x9b" not in shown


def test_secrets_are_scrubbed_on_the_way_out():
    register_secret("console-secret-value")
    assert "console-secret-value" not in safe("key console-secret-value")
    assert "sk-abcdefgh12345678" not in esc("sk-abcdefgh12345678")


def test_print_error_is_one_literal_line():
    out = io.StringIO()
    print_error("bad [/] thing\nsecond line \x1b]0;x\x07", make_console(file=out, width=80))
    text = out.getvalue()
    assert text.count("\n") == 1 and text.startswith("error: bad [/] thing second line")
