"""Two servers serving the same model name never share cached answers (issue 15, item 1)."""

from __future__ import annotations

import asyncio

from rover.vlm import load_vlm
from rover.vlm.cache import cache_key
from rover.vlm.testing import OpenAICompatServer
from rover.vlm.types import SamplingParams


def test_two_servers_with_the_same_model_name_keep_their_own_answers(fast_config, make_prompt):
    prompt = make_prompt("What happens?")
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        a.answer = lambda body: "answer from A"
        b.answer = lambda body: "answer from B"

        def ask(server):
            vlm = load_vlm(f"openai:same-name@{server.base_url}", fast_config)
            return asyncio.run(vlm.complete(prompt))

        first, second, again = ask(a), ask(b), ask(a)
        assert (first.text, first.cached) == ("answer from A", False)
        assert (second.text, second.cached) == ("answer from B", False)  # B was really asked
        assert (again.text, again.cached) == ("answer from A", True)  # A's answer, from disk
        assert (a.count, b.count) == (1, 1)


def test_the_same_server_under_other_spellings_shares_its_answers(fast_config, make_prompt):
    """Credentials, case and a trailing slash do not make another endpoint."""
    prompt = make_prompt("What happens?")
    with OpenAICompatServer() as server:
        port = server.port
        plain = load_vlm(f"openai:m@http://127.0.0.1:{port}/v1", fast_config)
        spelled = load_vlm(f"openai:m@HTTP://u:secret-pw@127.0.0.1:{port}/v1/", fast_config)
        assert plain.endpoint() == spelled.endpoint() == f"http://127.0.0.1:{port}/v1"
        asyncio.run(plain.complete(prompt))
        assert asyncio.run(spelled.complete(prompt)).cached
        assert server.count == 1


def test_every_input_of_an_answer_changes_the_key():
    base = dict(backend="openai", model="m", fingerprint="f", params=SamplingParams())
    key = cache_key(**base, endpoint="http://a/v1")
    variants = [
        cache_key(**{**base, "backend": "gemini"}, endpoint="http://a/v1"),
        cache_key(**{**base, "model": "m2"}, endpoint="http://a/v1"),
        cache_key(**{**base, "fingerprint": "g"}, endpoint="http://a/v1"),
        cache_key(**{**base, "params": SamplingParams(max_tokens=10)}, endpoint="http://a/v1"),
        cache_key(**{**base, "params": SamplingParams(temperature=0.7)}, endpoint="http://a/v1"),
        cache_key(**{**base, "params": SamplingParams(seed=1)}, endpoint="http://a/v1"),
        cache_key(**base, extra={"detail": "low"}, endpoint="http://a/v1"),
        cache_key(**base, endpoint="http://b/v1"),
    ]
    assert key not in variants and len(set(variants)) == len(variants)
