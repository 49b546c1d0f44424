"""The gemini backend through google-genai against a live loopback Gemini-REST server."""

from __future__ import annotations

import asyncio
import base64

import pytest

from rover.errors import BackendError
from rover.vlm import load_vlm
from rover.vlm.testing import Reply

pytest.importorskip("google.genai")

KEY = "AIzaTEST-gemini-key-000000000000"


@pytest.fixture
def gemini(gemini_server, fast_config, monkeypatch):
    monkeypatch.setenv("GEMINI_API_KEY", KEY)
    return load_vlm(f"gemini:gemini-2.0-flash@{gemini_server.base_url}", fast_config)


def test_answer_with_image_and_reported_usage(gemini, gemini_server, make_prompt):
    gemini_server.answer = lambda body: "Frame description: the gripper is open."
    completion = asyncio.run(gemini.complete(make_prompt(n_images=2)))

    assert completion.text == "Frame description: the gripper is open."
    assert (completion.backend, completion.model) == ("gemini", "gemini-2.0-flash")
    usage = completion.usage
    assert usage.source == "reported"
    assert (usage.prompt_tokens, usage.image_tokens) == (30 + 2 * 258, 2 * 258)
    assert usage.completion_tokens == 6

    body = gemini_server.requests[0]
    assert body["_path"] == "/v1beta/models/gemini-2.0-flash:generateContent"
    assert body["systemInstruction"]["parts"][0]["text"] == "You watch robot videos."
    parts = body["contents"][0]["parts"]
    inline = [p["inlineData"] for p in parts if "inlineData" in p]
    assert [i["mime_type"] for i in inline] == ["image/jpeg", "image/jpeg"]
    assert base64.urlsafe_b64decode(inline[0]["data"])[:2] == b"\xff\xd8"  # a JPEG
    assert parts[-1] == {"text": "Describe the frame."}
    assert body["generationConfig"]["maxOutputTokens"] == 512
    assert gemini_server.keys_seen == [KEY]
    assert "x-goog-api-key" not in body["_headers"]


def test_rate_limit_then_success_and_cache(gemini, gemini_server, make_prompt, fast_config):
    gemini_server.script(Reply(status=429, text="quota per minute", headers={"retry-after": "0"}))
    first = asyncio.run(gemini.complete(make_prompt()))
    assert first.text == "ok" and gemini_server.count == 2

    spec = f"gemini:gemini-2.0-flash@{gemini_server.base_url}"
    again = asyncio.run(load_vlm(spec, fast_config).complete(make_prompt()))
    assert again.cached and again.text == "ok"
    assert gemini_server.count == 2


def test_server_error_is_retried(gemini, gemini_server, make_prompt):
    gemini_server.script(Reply(status=500), Reply(status=500))
    assert asyncio.run(gemini.complete(make_prompt())).text == "ok"
    assert gemini_server.count == 3


@pytest.mark.parametrize("status", [401, 403, 404, 400])
def test_fatal_errors_fail_fast(gemini, gemini_server, make_prompt, status):
    gemini_server.script(Reply(status=status, text=f"rejected with key {KEY}"))
    with pytest.raises(BackendError, match=str(status)) as info:
        asyncio.run(gemini.complete(make_prompt()))
    assert gemini_server.count == 1
    assert KEY not in str(info.value)


def test_missing_key_names_the_variables(fast_config):
    with pytest.raises(BackendError, match="GEMINI_API_KEY or GOOGLE_API_KEY"):
        load_vlm("gemini:gemini-2.0-flash", fast_config)
