"""The openai backend through the official SDK against a live loopback server."""

from __future__ import annotations

import asyncio
import base64
import io

import pytest
from PIL import Image

from rover.errors import BackendError
from rover.vlm import load_vlm
from rover.vlm.testing import Reply


def run(coro):
    return asyncio.run(coro)


def test_answer_with_images_sends_data_urls_and_detail(openai_server, fast_config, make_prompt):
    config = fast_config.model_copy(update={"detail": "low", "no_cache": True})
    vlm = load_vlm(f"openai:qwen2.5-vl@{openai_server.base_url}", config)
    openai_server.answer = lambda body: f"saw {len(body['messages'][1]['content']) - 1} images"
    prompt = make_prompt(n_images=2)
    prompt.messages[1].content[1].detail = "high"  # a part's own detail wins

    completion = run(vlm.complete(prompt))

    assert completion.text == "saw 2 images"
    assert (completion.backend, completion.model, completion.cached) == (
        "openai",
        "qwen2.5-vl",
        False,
    )
    assert completion.usage.source == "reported"
    assert completion.usage.prompt_tokens == 40 + 100 * 2  # what the server reported
    body = openai_server.requests[0]
    assert body["_path"] == "/v1/chat/completions"
    assert body["model"] == "qwen2.5-vl"
    assert body["max_tokens"] == 512 and body["temperature"] == 0.0 and body["seed"] == 0
    assert body["messages"][0] == {"role": "system", "content": "You watch robot videos."}
    images = [c for c in body["messages"][1]["content"] if c["type"] == "image_url"]
    assert [c["image_url"]["detail"] for c in images] == ["low", "high"]
    url = images[0]["image_url"]["url"]
    assert url.startswith("data:image/jpeg;base64,")
    decoded = Image.open(io.BytesIO(base64.b64decode(url.split(",", 1)[1])))
    assert (decoded.format, decoded.size) == ("JPEG", (64, 48))
    assert body["messages"][1]["content"][-1] == {"type": "text", "text": "Describe the frame."}
    assert "authorization" not in body["_headers"]
    assert openai_server.keys_seen == ["Bearer not-needed"]  # local server, no key set


@pytest.mark.parametrize(
    "failure",
    [
        Reply(status=429, text="slow down", headers={"retry-after": "0"}),
        Reply(status=500, text="boom"),
        Reply(status=503, text="overloaded", headers={"retry-after-ms": "5"}),
    ],
    ids=["429", "500", "503"],
)
def test_transient_failure_is_retried(openai_server, fast_config, make_prompt, failure):
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    openai_server.script(failure)
    completion = run(vlm.complete(make_prompt()))
    assert completion.text == "ok"
    assert openai_server.count == 2


def test_timeout_is_retried_then_succeeds(openai_server, fast_config, make_prompt):
    config = fast_config.model_copy(update={"timeout_s": 0.3, "no_cache": True})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(Reply(delay_s=1.5))
    assert run(vlm.complete(make_prompt())).text == "ok"
    assert openai_server.count == 2


def test_persistent_timeout_gives_up_with_one_line(openai_server, fast_config, make_prompt):
    config = fast_config.model_copy(update={"timeout_s": 0.2, "max_retries": 1})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(Reply(delay_s=1.0), Reply(delay_s=1.0))
    with pytest.raises(BackendError, match="gave up after 2 attempt") as info:
        run(vlm.complete(make_prompt()))
    assert "\n" not in str(info.value)
    # at most two requests; on a loaded machine one may not even reach the server in 0.2 s
    assert openai_server.count <= 2


def test_bad_key_fails_fast(openai_server, fast_config, make_prompt, monkeypatch):
    monkeypatch.setenv("OPENAI_API_KEY", "sk-test-WRONGKEY0123456789")
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    openai_server.script(
        Reply(status=401, text="Incorrect API key provided: sk-test-WRONGKEY0123456789")
    )
    with pytest.raises(BackendError) as info:
        run(vlm.complete(make_prompt()))
    message = str(info.value)
    assert openai_server.count == 1
    assert "401" in message and "OPENAI_API_KEY" in message
    assert "WRONGKEY" not in message and "\n" not in message


def test_unknown_model_fails_fast(openai_server, fast_config, make_prompt):
    vlm = load_vlm(f"openai:no-such-model@{openai_server.base_url}", fast_config)
    openai_server.script(Reply(status=404, text="model 'no-such-model' not found"))
    with pytest.raises(BackendError, match="404.*model name"):
        run(vlm.complete(make_prompt()))
    assert openai_server.count == 1


def test_quota_exhausted_is_not_retried(openai_server, fast_config, make_prompt):
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    openai_server.script(
        Reply(status=429, text="You exceeded your quota", code="insufficient_quota")
    )
    with pytest.raises(BackendError, match="quota"):
        run(vlm.complete(make_prompt()))
    assert openai_server.count == 1


def test_rerun_is_answered_from_cache_without_requests(openai_server, fast_config, make_prompt):
    openai_server.answer = lambda body: f"answer for {body['messages'][1]['content'][0]['type']}"
    prompts = [make_prompt(first_frame=i, kind="rover.step") for i in range(4)]
    spec = f"openai:m@{openai_server.base_url}"

    async def ask_all(vlm):
        return await asyncio.gather(*(vlm.complete(p) for p in prompts))

    first = run(ask_all(load_vlm(spec, fast_config)))
    assert openai_server.count == 4 and not any(c.cached for c in first)

    again = run(ask_all(load_vlm(spec, fast_config)))  # a fresh process would do the same
    assert openai_server.count == 4
    assert all(c.cached for c in again)
    assert [c.text for c in again] == [c.text for c in first]
    assert [c.usage for c in again] == [c.usage for c in first]

    no_cache = fast_config.model_copy(update={"no_cache": True})
    run(ask_all(load_vlm(spec, no_cache)))
    assert openai_server.count == 8


def test_concurrency_limit_and_successive_event_loops(openai_server, fast_config, make_prompt):
    config = fast_config.model_copy(update={"concurrency": 2, "no_cache": True})
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    openai_server.script(*[Reply(delay_s=0.15) for _ in range(6)])

    async def burst():
        return await asyncio.gather(*(vlm.complete(make_prompt(first_frame=i)) for i in range(6)))

    assert len(run(burst())) == 6
    assert openai_server.max_in_flight == 2
    # the same VLM object keeps working from a new event loop (fresh semaphore and client)
    assert run(vlm.complete(make_prompt(first_frame=9))).text == "ok"


def test_missing_key_for_the_real_api_is_a_clear_error(fast_config):
    with pytest.raises(BackendError, match="OPENAI_API_KEY"):
        load_vlm("openai:gpt-4o", fast_config)


def test_key_from_a_configured_variable(openai_server, fast_config, make_prompt, monkeypatch):
    monkeypatch.setenv("MY_VLLM_TOKEN", "tok-abcdef123456")
    config = fast_config.model_copy(update={"api_key_env": "MY_VLLM_TOKEN"})
    run(load_vlm(f"openai:m@{openai_server.base_url}", config).complete(make_prompt()))
    assert openai_server.keys_seen == ["Bearer tok-abcdef123456"]


def test_reasoning_models_get_max_completion_tokens(openai_server, fast_config, make_prompt):
    run(
        load_vlm(f"openai:gpt-5-mini@{openai_server.base_url}", fast_config).complete(make_prompt())
    )
    body = openai_server.requests[0]
    assert body["max_completion_tokens"] == 512
    assert "max_tokens" not in body and "temperature" not in body


def test_unreported_usage_is_estimated(openai_server, fast_config, make_prompt):
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", fast_config)
    openai_server.script(Reply(text="Frame description: the gripper is open.", usage=False))
    usage = run(vlm.complete(make_prompt(n_images=2))).usage
    assert usage.source == "estimated"
    assert usage.image_tokens == 2 * 255  # 64x48 -> one 512 tile at high detail (auto)
    assert usage.completion_tokens > 0


def test_dead_endpoint_is_one_clear_line(fast_config, make_prompt):
    import socket

    with socket.socket() as s:  # a port nobody listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    config = fast_config.model_copy(update={"max_retries": 1})
    vlm = load_vlm(f"openai:m@http://127.0.0.1:{port}/v1", config)
    with pytest.raises(BackendError, match=f"cannot connect to http://127.0.0.1:{port}/v1"):
        run(vlm.complete(make_prompt()))
