"""One retry loop for every backend; backends only say what kind of failure they saw.

Rate limits, server errors, timeouts and dropped connections are retried with exponential
backoff and jitter (honouring a provider's Retry-After, capped), up to a bounded number of
attempts, each under its own timeout. Anything fatal — a bad key, an unknown model, a
malformed request — fails at once with one line (a `BackendError`), because retrying it
only burns time and quota. Messages pass through `keys.scrub` so a key never leaks.
"""

from __future__ import annotations

import asyncio
import email.utils
import logging
import random
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, TypeVar

from rover.errors import BackendError
from rover.vlm.keys import scrub

log = logging.getLogger(__name__)

T = TypeVar("T")


class ErrorKind(StrEnum):
    rate_limit = "rate_limit"
    transient = "transient"
    fatal = "fatal"


@dataclass(frozen=True)
class ErrorInfo:
    """A backend's verdict on one exception."""

    kind: ErrorKind
    message: str
    retry_after: float | None = None  # seconds the provider asked us to wait


@dataclass(frozen=True)
class RetryPolicy:
    max_retries: int = 6
    timeout_s: float | None = 120.0
    base_wait_s: float = 1.0
    max_wait_s: float = 60.0


def parse_retry_after(headers: Any) -> float | None:
    """Seconds from `retry-after-ms` / `retry-after` (seconds or an HTTP date), if present."""
    if headers is None:
        return None
    try:
        ms = headers.get("retry-after-ms")
        if ms is not None:
            return max(0.0, float(ms) / 1000)
        value = headers.get("retry-after")
    except Exception:
        return None
    if value is None:
        return None
    try:
        return max(0.0, float(value))
    except ValueError:
        pass
    try:
        when = email.utils.parsedate_to_datetime(value)
    except (TypeError, ValueError):
        return None
    return max(0.0, when.timestamp() - time.time())


def backoff_wait(attempt: int, policy: RetryPolicy, retry_after: float | None, rng: Any) -> float:
    """How long to sleep before retry number `attempt` (0-based)."""
    if retry_after is not None:
        return min(retry_after, policy.max_wait_s)
    cap = min(policy.max_wait_s, policy.base_wait_s * (2**attempt))
    return cap * (0.5 + 0.5 * rng.random())  # jitter keeps parallel callers from syncing


async def call_with_retries(
    call: Callable[[], Awaitable[T]],
    classify: Callable[[BaseException], ErrorInfo | None],
    policy: RetryPolicy,
    label: str,
    rng: random.Random | None = None,
) -> T:
    """Run `call` until it succeeds, a fatal error occurs, or the attempts run out.

    Args:
        call: makes one attempt (a fresh coroutine each time).
        classify: the backend's verdict on an exception; None means "not an API error"
            (a bug on our side), which propagates unchanged.
        policy: attempts, per-attempt timeout and backoff bounds.
        label: "backend:model", the prefix of every message.
        rng: jitter source (seeded in tests).

    Raises:
        BackendError: on a fatal error, or when every attempt failed.
    """
    rng = rng or random.Random()
    attempts = policy.max_retries + 1
    last = ""
    for attempt in range(attempts):
        try:
            if policy.timeout_s is None:
                return await call()
            return await asyncio.wait_for(call(), timeout=policy.timeout_s)
        except TimeoutError:
            info = ErrorInfo(ErrorKind.transient, f"no answer within {policy.timeout_s:g} s")
        except asyncio.CancelledError:
            raise
        except Exception as exc:
            verdict = classify(exc)
            if verdict is None:
                raise
            info = verdict
        last = scrub(info.message)
        if info.kind is ErrorKind.fatal:
            raise BackendError(f"{label}: {last}") from None
        if attempt + 1 >= attempts:
            break
        wait = backoff_wait(attempt, policy, info.retry_after, rng)
        log.warning(
            "%s: %s; retry %d/%d in %.1f s", label, last, attempt + 1, policy.max_retries, wait
        )
        await asyncio.sleep(wait)
    raise BackendError(f"{label}: gave up after {attempts} attempt(s): {last}")
