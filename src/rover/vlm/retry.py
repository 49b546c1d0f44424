"""One retry loop for every backend; backends only say what kind of failure they saw.

Rate limits, server errors, timeouts and dropped connections are retried with exponential
backoff and jitter (honouring a provider's Retry-After, capped), up to a bounded number of
attempts, each under its own timeout. Anything fatal — a bad key, an unknown model, a
malformed request — fails at once with one line (a `BackendError`), because retrying it
only burns time and quota. Some transient failures get a smaller retry budget of their
own: a timeout (a silent server rarely wakes up, and each try costs a full timeout), an
unreachable endpoint, a malformed body. Messages pass through `scrub_line` (scrubbed, then
cut to one line) so a key never leaks and a hostile body cannot reach the terminal raw.
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
from rover.vlm.scrub import scrub_line

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
    # at most this many retries for failures of this `group` (None: the policy's max_retries)
    retry_limit: int | None = None
    group: str = ""


class MalformedReply(Exception):
    """A provider answered, but not with a body we can read (bad JSON, wrong shape, bytes).

    Backends raise it from `_generate`; the retry loop treats it as transient with a small
    budget of its own, then fails with one line.
    """


MALFORMED_RETRIES = 2


def classify_common(exc: BaseException) -> ErrorInfo | None:
    """Failures any backend can meet while reading a body: malformed, undecodable, truncated."""
    if isinstance(exc, MalformedReply):
        detail = str(exc)
    elif isinstance(exc, UnicodeDecodeError):
        detail = "body is not valid UTF-8"
    elif isinstance(exc, ValueError) and type(exc).__name__ == "JSONDecodeError":
        detail = f"body is not valid JSON ({exc})"
    else:
        return None
    return ErrorInfo(
        ErrorKind.transient,
        f"malformed response from the server: {detail}",
        retry_limit=MALFORMED_RETRIES,
        group="malformed",
    )


@dataclass(frozen=True)
class RetryPolicy:
    max_retries: int = 6
    timeout_s: float | None = 60.0
    base_wait_s: float = 1.0
    max_wait_s: float = 60.0
    # retries after a timeout (each costs a whole timeout_s; a silent server stays silent)
    timeout_retries: int = 1
    # False: the call times its own attempts (an endpoint pool times each replica, so a
    # failover gets a fresh timeout); timeout_s then only names the limit in messages
    wrap_timeout: bool = True


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
    seen: dict[str, int] = {}  # failures so far per group with its own retry budget
    attempt = 0
    for attempt in range(attempts):
        try:
            if policy.timeout_s is None or not policy.wrap_timeout:
                return await call()
            return await asyncio.wait_for(call(), timeout=policy.timeout_s)
        except TimeoutError:
            within = f" within {policy.timeout_s:g} s" if policy.timeout_s is not None else ""
            info = ErrorInfo(
                ErrorKind.transient,
                f"no answer{within} (raise it with --timeout)",
                retry_limit=policy.timeout_retries,
                group="timeout",
            )
        except asyncio.CancelledError:
            raise
        except Exception as exc:
            verdict = classify(exc)
            if verdict is None:
                raise
            info = verdict
        last = scrub_line(info.message)
        if info.kind is ErrorKind.fatal:
            raise BackendError(f"{label}: {last}") from None
        if attempt + 1 >= attempts:
            break
        limit = info.retry_limit
        if limit is None and info.group == "timeout":  # a timeout the SDK noticed first
            limit = policy.timeout_retries
        if limit is not None:
            seen[info.group] = seen.get(info.group, 0) + 1
            if seen[info.group] > limit:
                break
        wait = backoff_wait(attempt, policy, info.retry_after, rng)
        log.warning(
            "%s: %s; retry %d/%d in %.1f s", label, last, attempt + 1, policy.max_retries, wait
        )
        await asyncio.sleep(wait)
    raise BackendError(f"{label}: gave up after {attempt + 1} attempt(s): {last}")
