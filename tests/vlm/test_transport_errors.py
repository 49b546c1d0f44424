"""Unreadable bodies, dead endpoints and silent servers fail in one line, quickly (items 6-8)."""

from __future__ import annotations

import asyncio
import socket

import pytest

from rover.errors import BackendError, InputError
from rover.vlm import load_vlm
from rover.vlm.loader import parse_spec
from rover.vlm.retry import MALFORMED_RETRIES
from rover.vlm.testing import Reply

MALFORMED = [
    Reply(raw=b'{"choices": [{"message": {"content": "\xff\xfe"}}]}'),  # not UTF-8
    Reply(raw=b"plain words", content_type="text/plain"),  # a 200 that is not JSON
    Reply(raw=b"[1, 2, 3]"),  # JSON, but an array
    Reply(raw=b"null"),
    Reply(raw=b'{"choices": null}'),
    Reply(raw=b'{"choices": [{"message": "text"}]}'),
    Reply(raw=b'{"choices": [{"message": {"content": 12}}]}'),
    Reply(raw=b'{"choices": [{"mess'),  # cut off
]


@pytest.mark.parametrize("reply", MALFORMED, ids=lambda r: r.raw[:24].decode("latin-1"))
def test_a_malformed_body_gets_a_bounded_retry_then_one_line(
    openai_server, fast_config, make_prompt, reply
):
    config = fast_config.model_copy(update={"max_retries": 6})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(*[reply] * 10)
    with pytest.raises(BackendError) as info:
        asyncio.run(vlm.complete(make_prompt()))
    message = str(info.value)
    assert "malformed response" in message and "\n" not in message
    assert openai_server.count == 1 + MALFORMED_RETRIES  # not 1 + max_retries


def test_a_malformed_body_then_a_good_one_recovers(openai_server, fast_config, make_prompt):
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    openai_server.script(Reply(raw=b"[]"), Reply(text="fine"))
    assert asyncio.run(vlm.complete(make_prompt())).text == "fine"


def test_usage_that_is_not_a_count_is_estimated(openai_server, fast_config, make_prompt):
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    body = b'{"choices": [{"message": {"content": "ok"}}], "usage": {"prompt_tokens": "many"}}'
    openai_server.script(Reply(raw=body))
    completion = asyncio.run(vlm.complete(make_prompt()))
    assert completion.text == "ok" and completion.usage.source == "estimated"


def test_a_dead_endpoint_fails_after_a_few_quick_tries(fast_config, make_prompt):
    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    config = fast_config.model_copy(update={"max_retries": 6})
    vlm = load_vlm(f"openai:m@http://user:pw-dead-123@127.0.0.1:{port}/v1", config)
    with pytest.raises(BackendError) as info:
        asyncio.run(vlm.complete(make_prompt()))
    message = str(info.value)
    assert "cannot connect" in message and "gave up after 3 attempt(s)" in message
    assert "pw-dead-123" not in message


def test_a_silent_server_is_retried_once_not_six_times(openai_server, fast_config, make_prompt):
    config = fast_config.model_copy(update={"timeout_s": 0.3, "max_retries": 6})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(*[Reply(delay_s=1.0)] * 3)
    with pytest.raises(BackendError) as info:
        asyncio.run(vlm.complete(make_prompt()))
    message = str(info.value)
    assert "gave up after 2 attempt(s)" in message
    assert "--timeout" in message and "--timeout-s" not in message


def test_defaults_separate_connect_from_read_timeouts():
    from rover.vlm.config import BackendConfig

    config = BackendConfig()
    assert config.connect_timeout_s < config.timeout_s
    assert config.timeout_retries <= 1


@pytest.mark.parametrize(
    "spec",
    [
        "openai:m@127.0.0.1:8000/v1",
        "openai:m@localhost",
        "openai:m@localhost:8000",
        "openai:m@host.example/v1",
        "gemini:m@127.0.0.1:9000",
        "openai:m@ftp://host/v1",
    ],
)
def test_a_server_without_a_scheme_is_refused(spec, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-real-key-must-not-travel-000")
    with pytest.raises(InputError, match="scheme"):
        load_vlm(spec)


def test_model_names_with_an_at_sign_are_still_names():
    assert parse_spec("openai:claude@2024") == ("openai", "claude@2024", None)
    assert parse_spec("openai:m@HTTPS://h/v1") == ("openai", "m", "HTTPS://h/v1")


def test_a_url_that_names_no_host_is_refused():
    with pytest.raises(InputError, match="host"):
        load_vlm("openai:m@http://")
