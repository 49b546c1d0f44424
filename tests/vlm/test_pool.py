"""Endpoint pools (issue 14, item 2): replicas of one model behind one backend spec.

Real loopback servers: a healthy one, one that answers 503, one that is slow, one whose
port is closed; calls run concurrently through the real OpenAI SDK.
"""

from __future__ import annotations

import asyncio
import logging
import socket
from pathlib import Path

import pytest

from rover.errors import BackendError, InputError
from rover.vlm import BackendConfig, load_vlm
from rover.vlm.config import default_backend
from rover.vlm.pool import EndpointPool
from rover.vlm.testing import OpenAICompatServer, Reply


def _closed_port_url() -> str:
    """A URL nothing listens on (connection refused)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    return f"http://127.0.0.1:{port}/v1"


def _ask_many(vlm, prompts):
    """Ask concurrently. Tests that count requests per replica give a long timeout: the
    SDK's first request imports its resource modules, which takes seconds on a busy CPU."""

    async def go():
        try:
            return await asyncio.gather(*(vlm.complete(p) for p in prompts))
        finally:
            await vlm.aclose()

    return asyncio.run(go())


def _prompts(make_prompt, n: int):
    return [make_prompt(f"question {i}?") for i in range(n)]


def test_equal_replicas_share_concurrent_calls_evenly(fast_config, make_prompt):
    config = fast_config.model_copy(update={"concurrency": 8, "no_cache": True, "timeout_s": 60.0})
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        for s, name in ((a, "A"), (b, "B")):
            s.answer = lambda body, name=name: f"from {name}"
            s.script(*[Reply(delay_s=0.2)] * 4)  # slow enough that all 8 are in flight at once
        vlm = load_vlm(f"openai:m@{a.base_url},{b.base_url}", config)
        out = _ask_many(vlm, _prompts(make_prompt, 8))
        assert (a.count, b.count) == (4, 4)  # least outstanding, ties rotated
        assert sorted(c.text for c in out) == ["from A"] * 4 + ["from B"] * 4
        assert a.max_in_flight == b.max_in_flight == 4


def test_a_slow_replica_gets_fewer_calls(fast_config, make_prompt):
    config = fast_config.model_copy(update={"concurrency": 2, "no_cache": True, "timeout_s": 60.0})
    with OpenAICompatServer() as slow, OpenAICompatServer() as fast:
        slow.script(*[Reply(delay_s=1.0)] * 10)
        vlm = load_vlm(f"openai:m@{slow.base_url},{fast.base_url}", config)
        _ask_many(vlm, _prompts(make_prompt, 12))
        assert slow.count + fast.count == 12
        assert slow.count <= 3 < fast.count  # the busy replica is passed over while it works


def test_a_failing_replica_is_failed_over_and_cooled_down(fast_config, make_prompt, caplog):
    config = fast_config.model_copy(update={"concurrency": 1, "no_cache": True})
    with OpenAICompatServer() as bad, OpenAICompatServer() as good:
        bad.script(*[Reply(status=503, text="overloaded")] * 20)
        good.answer = lambda body: "fine"
        url = bad.base_url.replace("http://", "http://user:s3cret-pw@")
        vlm = load_vlm(f"openai:m@{url},{good.base_url}", config)
        with caplog.at_level(logging.WARNING):
            out = _ask_many(vlm, _prompts(make_prompt, 6))
        assert [c.text for c in out] == ["fine"] * 6
        assert bad.count == 1  # tried once, then cooled down for the rest
        assert good.count == 6
        assert vlm.pool.replicas[0].failures == 1
        assert "trying another replica" in caplog.text
        assert "s3cret-pw" not in caplog.text


def test_a_dead_replica_fails_over_to_a_live_one(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True, "concurrency": 4})
    with OpenAICompatServer() as live:
        vlm = load_vlm(f"openai:m@{_closed_port_url()},{live.base_url}", config)
        out = _ask_many(vlm, _prompts(make_prompt, 5))
        assert all(c.text == "ok" for c in out) and live.count == 5
        dead = vlm.pool.replicas[0]
        assert dead.served == 0 and 1 <= dead.failures <= 4  # only calls already in flight


def test_a_replica_that_times_out_is_failed_over_within_one_call(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True, "timeout_s": 0.5})
    with OpenAICompatServer() as stuck, OpenAICompatServer() as good:
        stuck.script(Reply(delay_s=3.0))
        good.answer = lambda body: "in time"
        # warm the SDK up first (its first request imports modules: seconds on a busy CPU)
        warm = fast_config.model_copy(update={"no_cache": True, "timeout_s": 60.0})
        _ask_many(load_vlm(f"openai:m@{good.base_url}", warm), [make_prompt("warm-up")])
        vlm = load_vlm(f"openai:m@{stuck.base_url},{good.base_url}", config)
        (out,) = _ask_many(vlm, [make_prompt("hello?")])
        assert out.text == "in time" and (stuck.count, good.count) == (1, 2)
        assert vlm.pool.replicas[0].failures == 1


def test_when_every_replica_fails_the_call_gives_up_bounded(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True, "max_retries": 2})
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        for s in (a, b):
            s.script(*[Reply(status=500, text="boom")] * 20)
        vlm = load_vlm(f"openai:m@{a.base_url},{b.base_url}", config)
        with pytest.raises(BackendError, match="gave up after 3 attempt"):
            _ask_many(vlm, [make_prompt("x")])
        # each of the 3 attempts tries every replica not cooling down; at most 2 per attempt
        assert 3 <= a.count + b.count <= 6


def test_errors_no_replica_can_fix_are_not_retried_elsewhere(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True})
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        a.script(Reply(status=401, text="bad key"))
        b.script(Reply(status=401, text="bad key"))
        vlm = load_vlm(f"openai:m@{a.base_url},{b.base_url}", config)
        with pytest.raises(BackendError, match="authentication failed"):
            _ask_many(vlm, [make_prompt("x")])
        assert a.count + b.count == 1


def test_the_cache_key_is_the_pool_not_the_replica(fast_config, make_prompt):
    prompt = make_prompt("What happens?")
    with OpenAICompatServer() as a, OpenAICompatServer() as b, OpenAICompatServer() as c:
        first = load_vlm(f"openai:m@{a.base_url},{b.base_url}", fast_config)
        (answer,) = _ask_many(first, [prompt])
        assert not answer.cached
        # the same pool listed the other way round (and with credentials) is the same model
        spelled = b.base_url.replace("http://", "http://u:pw@") + "/"
        again = load_vlm(f"openai:m@{spelled},{a.base_url}", fast_config)
        assert again.endpoint() == first.endpoint()
        (hit,) = _ask_many(again, [prompt])
        assert hit.cached and a.count + b.count == 1
        assert "pw" not in first.endpoint()
        # another deployment (a different set of servers) keeps its own answers
        other = load_vlm(f"openai:m@{a.base_url},{c.base_url}", fast_config)
        (fresh,) = _ask_many(other, [prompt])
        assert not fresh.cached


def test_a_pool_of_one_is_keyed_like_the_plain_url(fast_config):
    with OpenAICompatServer() as a:
        plain = load_vlm(f"openai:m@{a.base_url}", fast_config)
        listed = load_vlm("openai:m", fast_config.model_copy(update={"base_url": [a.base_url]}))
        assert plain.endpoint() == listed.endpoint() == a.base_url
        assert listed.pool is None


def test_bad_pool_specs_fail_with_one_line(fast_config):
    with pytest.raises(InputError, match="explicit scheme"):
        load_vlm("openai:m@http://a:8000/v1,b:8000/v1", fast_config)
    with pytest.raises(InputError, match="twice"):
        load_vlm("openai:m@http://a:8000/v1,HTTP://a:8000/v1/", fast_config)
    pool = fast_config.model_copy(update={"base_url": ["http://a/v1", "http://b/v1"]})
    with pytest.raises(InputError, match="OpenAI-compatible"):
        load_vlm("gemini:g", pool)


def test_routing_rules_with_a_fake_clock():
    now = [0.0]
    pool = EndpointPool(["http://a/v1", "http://b/v1", "http://c/v1"], "t", 10.0, lambda: now[0])
    first = [pool.pick(set()) for _ in range(3)]
    assert sorted(first) == [0, 1, 2]  # one each before any replica gets a second
    for i in first:
        pool._done(i, ok=True, cool=False)
    b = pool.pick(set())
    pool._done(b, ok=False, cool=True)  # b fails: cooled for 10 s
    picks = []
    for _ in range(4):
        i = pool.pick(set())
        picks.append(i)
        pool._done(i, ok=True, cool=False)
    assert b not in picks
    now[0] = 10.5  # cooldown over: b is back in rotation
    picks = {pool.pick(set()) for _ in range(3)}
    assert picks == {0, 1, 2}


def test_every_replica_cooling_still_tries_the_one_that_recovers_first():
    now = [0.0]
    pool = EndpointPool(["http://a/v1", "http://b/v1"], "t", 10.0, lambda: now[0])
    for i in (0, 1):
        pool.replicas[i].cool_until = 5.0 + i
    assert pool.pick(set()) == 0  # a first attempt always goes somewhere
    assert pool.pick({0}) is None  # but no failover to a replica that is cooling down


def test_config_file_base_urls_make_a_pool(tmp_path: Path, monkeypatch):
    cfg = tmp_path / "config.toml"
    cfg.write_text(
        'backend = "openai:qwen"\nbase_urls = ["http://a:8000/v1", "http://b:8000/v1"]\n'
    )
    monkeypatch.setenv("ROVER_CONFIG", str(cfg))
    monkeypatch.delenv("ROVER_BACKEND", raising=False)
    assert default_backend() == "openai:qwen@http://a:8000/v1,http://b:8000/v1"
    vlm = load_vlm(default_backend(), BackendConfig(no_cache=True))
    assert len(vlm.pool) == 2
    cfg.write_text('backend = "openai:qwen@http://a/v1"\nbase_urls = ["http://b/v1"]\n')
    with pytest.raises(InputError, match="once"):
        default_backend()


def test_a_pool_nobody_answers_fails_with_one_line_naming_it(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True, "max_retries": 1})
    dead = [_closed_port_url(), _closed_port_url().replace("http://", "http://u:dead-pw@")]
    vlm = load_vlm(f"openai:m@{dead[0]},{dead[1]}", config)
    with pytest.raises(BackendError) as err:
        _ask_many(vlm, [make_prompt("x")])
    message = str(err.value)
    assert "cannot connect to the pool (http://127.0.0.1:" in message
    assert "dead-pw" not in message and "\n" not in message


def test_three_replicas_one_failing_one_slow_under_concurrency(fast_config, make_prompt):
    config = fast_config.model_copy(update={"concurrency": 3, "no_cache": True, "timeout_s": 60.0})
    with OpenAICompatServer() as bad, OpenAICompatServer() as slow, OpenAICompatServer() as ok:
        bad.script(*[Reply(status=502, text="bad gateway")] * 20)
        slow.script(*[Reply(delay_s=0.8)] * 20)
        for s, name in ((slow, "slow"), (ok, "ok")):
            s.answer = lambda body, name=name: name
        vlm = load_vlm(f"openai:m@{bad.base_url},{slow.base_url},{ok.base_url}", config)
        out = _ask_many(vlm, _prompts(make_prompt, 12))
        assert len(out) == 12 and {c.text for c in out} <= {"slow", "ok"}
        assert bad.count == 1  # failed over at once, then cooled down
        assert slow.count < ok.count and slow.count + ok.count == 12
        assert max(slow.max_in_flight, ok.max_in_flight) <= 3  # --concurrency bounds the pool


def test_a_pool_whose_replicas_all_time_out_says_so(fast_config, make_prompt):
    config = fast_config.model_copy(update={"no_cache": True, "timeout_s": 0.3})
    with OpenAICompatServer() as a, OpenAICompatServer() as b:
        warm = config.model_copy(update={"timeout_s": 60.0})
        _ask_many(load_vlm(f"openai:m@{a.base_url}", warm), [make_prompt("warm-up")])
        for s in (a, b):
            s.script(*[Reply(delay_s=2.0)] * 4)
        vlm = load_vlm(f"openai:m@{a.base_url},{b.base_url}", config)
        with pytest.raises(BackendError, match=r"no answer within 0.3 s"):
            _ask_many(vlm, [make_prompt("x")])
        # one failover per attempt; the timeout budget (1 retry) bounds the attempts
        assert a.count + b.count - 1 <= 4
