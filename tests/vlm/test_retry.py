"""The shared retry loop, driven by a scripted fake call (no network needed)."""

from __future__ import annotations

import asyncio
import random
from datetime import UTC, datetime, timedelta
from email.utils import format_datetime

import pytest

from rover.errors import BackendError
from rover.vlm.retry import (
    ErrorInfo,
    ErrorKind,
    RetryPolicy,
    backoff_wait,
    call_with_retries,
    parse_retry_after,
)


class Flaky:
    def __init__(self, failures: list[Exception]) -> None:
        self.failures = failures
        self.calls = 0

    async def __call__(self) -> str:
        self.calls += 1
        if self.failures:
            raise self.failures.pop(0)
        return "done"


def classify(exc: BaseException) -> ErrorInfo | None:
    if isinstance(exc, ConnectionError):
        return ErrorInfo(ErrorKind.transient, "connection reset")
    if isinstance(exc, PermissionError):
        return ErrorInfo(ErrorKind.fatal, "bad key sk-live-abcdefghijklmnop")
    return None


FAST = RetryPolicy(max_retries=3, timeout_s=1.0, base_wait_s=0.001, max_wait_s=0.002)


def test_transient_errors_retry_until_success():
    call = Flaky([ConnectionError(), ConnectionError()])
    assert asyncio.run(call_with_retries(call, classify, FAST, "x:y")) == "done"
    assert call.calls == 3


def test_attempts_are_bounded():
    call = Flaky([ConnectionError()] * 10)
    with pytest.raises(BackendError, match="x:y: gave up after 4 attempt"):
        asyncio.run(call_with_retries(call, classify, FAST, "x:y"))
    assert call.calls == 4


def test_fatal_fails_at_once_and_is_scrubbed():
    call = Flaky([PermissionError()])
    with pytest.raises(BackendError) as info:
        asyncio.run(call_with_retries(call, classify, FAST, "x:y"))
    assert call.calls == 1 and "sk-live" not in str(info.value)


def test_unclassified_errors_propagate_unchanged():
    call = Flaky([KeyError("bug")])
    with pytest.raises(KeyError):
        asyncio.run(call_with_retries(call, classify, FAST, "x:y"))


def test_per_call_timeout_counts_as_transient():
    calls = 0

    async def slow_then_fast() -> str:
        nonlocal calls
        calls += 1
        if calls == 1:
            await asyncio.sleep(5)
        return "late but fine"

    policy = RetryPolicy(max_retries=1, timeout_s=0.05, base_wait_s=0.001, max_wait_s=0.001)
    assert (
        asyncio.run(call_with_retries(slow_then_fast, classify, policy, "x:y")) == "late but fine"
    )
    assert calls == 2


def test_backoff_grows_with_jitter_and_is_capped():
    policy = RetryPolicy(base_wait_s=1.0, max_wait_s=10.0)
    rng = random.Random(0)
    waits = [backoff_wait(a, policy, None, rng) for a in range(6)]
    for attempt, wait in enumerate(waits):
        cap = min(10.0, 2.0**attempt)
        assert cap / 2 <= wait <= cap
    assert backoff_wait(0, policy, retry_after=3.0, rng=rng) == 3.0
    assert backoff_wait(0, policy, retry_after=600.0, rng=rng) == 10.0  # capped


def test_parse_retry_after_forms():
    assert parse_retry_after({"retry-after": "7"}) == 7.0
    assert parse_retry_after({"retry-after-ms": "250", "retry-after": "7"}) == 0.25
    when = format_datetime(datetime.now(UTC) + timedelta(seconds=30), usegmt=True)
    assert 25 <= parse_retry_after({"retry-after": when}) <= 31
    assert parse_retry_after({"retry-after": "soon"}) is None
    assert parse_retry_after({}) is None and parse_retry_after(None) is None
