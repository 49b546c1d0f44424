"""API keys never reach files, logs or error messages."""

from __future__ import annotations

import asyncio
import logging

import pytest

from rover.errors import BackendError
from rover.vlm import load_vlm
from rover.vlm.keys import REDACTED, ScrubFilter, register_secret, scrub
from rover.vlm.testing import Reply

SECRET = "sk-test-SECRET123456789abcdef"


def test_a_run_with_a_key_leaves_it_nowhere(
    openai_server, fast_config, make_prompt, tmp_path, monkeypatch, caplog
):
    monkeypatch.setenv("OPENAI_API_KEY", SECRET)
    caplog.set_level(logging.DEBUG)  # everything, SDK and HTTP debug logs included
    config = fast_config.model_copy(update={"record": tmp_path / "run" / "cassette.jsonl"})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(
        Reply(status=429, text=f"slow down, {SECRET}", headers={"retry-after": "0"}),
        Reply(status=500, text=f"upstream said Bearer {SECRET}"),
    )

    async def session():
        for i in range(3):
            await vlm.complete(make_prompt(first_frame=i))

    asyncio.run(session())
    openai_server.script(Reply(status=401, text=f"Incorrect API key provided: {SECRET}"))
    with pytest.raises(BackendError) as info:
        asyncio.run(vlm.complete(make_prompt(first_frame=99)))

    assert openai_server.keys_seen[0] == f"Bearer {SECRET}"  # it was really used...
    written = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert {p.name for p in written} >= {"responses.sqlite", "cassette.jsonl"}
    for path in written:  # ...and is in no file (db, WAL, cassette)
        assert SECRET.encode() not in path.read_bytes(), path
    assert SECRET not in str(info.value)
    assert SECRET not in repr(vlm) and SECRET not in vlm.config.model_dump_json()
    assert caplog.records, "expected the SDK and retry loop to log"
    for record in caplog.records:
        assert SECRET not in record.getMessage(), record.name
    assert SECRET not in caplog.text


def test_scrub_removes_known_and_key_shaped_strings():
    register_secret("custom-token-value-42")
    text = "a custom-token-value-42 b sk-proj-abcdefgh12345 c AIzaSyA1234567890abcdefghij d"
    out = scrub(text)
    assert "custom-token-value-42" not in out and "sk-proj" not in out and "AIza" not in out
    assert out.count(REDACTED) == 3
    ordinary = "subtask-completion-percentage and mask-rcnn-features stay as they are"
    assert scrub(ordinary) == ordinary


def test_log_filter_rewrites_records():
    register_secret("another-secret-value")
    record = logging.LogRecord(
        "openai", logging.DEBUG, "", 0, "headers %s", ("another-secret-value",), None
    )
    assert ScrubFilter().filter(record)
    assert record.getMessage() == f"headers {REDACTED}"
