"""The one scrubber: every secret shape, removed before truncation (issue 15, item 5)."""

from __future__ import annotations

import pytest

from rover.vlm.keys import register_url_secret
from rover.vlm.scrub import REDACTED, register_secret, scrub, scrub_line, strip_controls


@pytest.mark.parametrize(
    ("text", "secret"),
    [
        ("failed at http://alice:hunter2-pw@host:8000/v1/chat", "hunter2-pw"),
        ("openai:m@https://tok3nValue@gateway.example/v1", "tok3nValue"),
        ("headers: {'Authorization': 'Basic dXNlcjpwYXNz'}", "dXNlcjpwYXNz"),
        ('"authorization": "Bearer abc.def-ghi_123"', "abc.def-ghi_123"),
        ("Authorization: Token 9f8e7d6c5b4a", "9f8e7d6c5b4a"),
        ("x-goog-api-key: AIzaSyA1234567890abcdefghij", "AIzaSyA1234567890abcdefghij"),
        ("api-key=azure0123456789", "azure0123456789"),
        ("the upstream said Bearer eyJhbGciOiJIUzI1NiJ9.payload", "eyJhbGciOiJIUzI1NiJ9"),
        ("key sk-proj-abcdefgh12345 in a sentence", "sk-proj-abcdefgh12345"),
        ("google AIzaSyA1234567890abcdefghij here", "AIzaSyA1234567890abcdefghij"),
        ("hf hf_abcdefghijklmnopqrstu token", "hf_abcdefghijklmnopqrstu"),
        ("GET /v1beta/models/m:generateContent?key=AIzaNotLongEnough&alt=sse", "AIzaNotLong"),
    ],
)
def test_each_shape_is_scrubbed(text, secret):
    out = scrub(text)
    assert secret not in out and REDACTED in out


def test_ordinary_text_is_left_alone():
    ordinary = (
        "Frame description: the basic approach works; the bearer of news said the task-key "
        "subtask-completion-percentage is 40%. See http://example.com/docs and user@example.com."
    )
    assert scrub(ordinary) == ordinary


def test_known_secrets_and_url_passwords_are_scrubbed_anywhere():
    register_secret("custom-token-value-42")
    register_url_secret("http://bob:p%40ss-w0rd-xyz@host/v1")
    out = scrub("a custom-token-value-42 b, and the password p@ss-w0rd-xyz on its own")
    assert "custom-token-value-42" not in out and "p@ss-w0rd-xyz" not in out


def test_scrubbing_happens_before_the_cut():
    """A key straddling the cut used to leave its prefix behind."""
    secret = "sk-live-" + "A1b2C3d4" * 4
    text = "x" * 290 + " " + secret
    line = scrub_line(text, 300)
    assert len(line) <= 300
    assert "sk-live" not in line and "A1b2" not in line


def test_control_characters_and_escape_sequences_are_stripped():
    hostile = "a\x1b]0;title\x07b\x1b[2Jc\x1b[31md\x00e\x9bf\u202eg\tline\nnext"
    assert strip_controls(hostile) == "abcdefg\tline\nnext"
    assert scrub_line(hostile) == "abcdefg line next"
