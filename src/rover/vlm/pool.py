"""A pool of replicas serving one model: least-outstanding routing and failover.

`openai:qwen@http://a:8000/v1,http://b:8000/v1` (or `BackendConfig.base_url` as a list)
names several vLLM/SGLang replicas of the same model. Each call goes to the replica with
the fewest requests in flight (ties rotate, so equal replicas share evenly). A replica
that fails in a way another could fix — it cannot be reached, answers 5xx or 429, times
out, or sends an unreadable body — is cooled down for `cooldown_s` and the call moves on
to the next replica at once, each replica at most once per call; when all of them failed,
the last error goes to the shared retry loop (backoff, bounded attempts), whose next
attempt starts over from the replicas that cooled down longest ago. Errors only a
different request would fix (a bad key, an unknown model) propagate unchanged.

The pool is one deployment: its cache identity is the sorted set of its replicas'
identities (credentials removed), never the replica that happened to answer, so an answer
is found again whichever replica serves the rerun. A pool of one URL is keyed exactly as
that URL always was.
"""

from __future__ import annotations

import asyncio
import logging
import threading
import time
from collections.abc import Awaitable, Callable
from dataclasses import dataclass
from typing import TypeVar

from rover.errors import InputError
from rover.vlm.endpoint import check_base_url, endpoint_identity
from rover.vlm.retry import ErrorInfo, ErrorKind
from rover.vlm.scrub import scrub_line

log = logging.getLogger(__name__)

T = TypeVar("T")

DEFAULT_COOLDOWN_S = 30.0


@dataclass
class Replica:
    """One server of the pool and what the pool knows about it."""

    url: str  # as given (may hold credentials: never shown, never part of a key)
    identity: str  # the URL without credentials, as messages show it
    outstanding: int = 0  # requests in flight now
    cool_until: float = 0.0  # monotonic time before which it is only used as a last resort
    served: int = 0  # answers it returned
    failures: int = 0  # attempts that failed over to another replica


def split_urls(value: str | list[str] | tuple[str, ...] | None) -> list[str]:
    """Base URLs from a comma-separated string or a list (blank entries dropped)."""
    if value is None:
        return []
    items = value.split(",") if isinstance(value, str) else list(value)
    return [u.strip() for u in items if isinstance(u, str) and u.strip()]


class EndpointPool:
    """Routes calls over replicas of one model; see the module docstring for the rules."""

    def __init__(
        self,
        urls: list[str],
        label: str,
        cooldown_s: float = DEFAULT_COOLDOWN_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        checked = [check_base_url(u, label) for u in urls]
        if not checked:
            raise InputError(f"{label}: an endpoint pool needs at least one base URL")
        seen: dict[str, str] = {}
        for url in checked:
            ident = endpoint_identity(url)
            if ident in seen:
                raise InputError(f"{label}: the pool names {ident} twice")
            seen[ident] = url
        self.label = label
        self.replicas = [Replica(url=u, identity=i) for i, u in seen.items()]
        self.cooldown_s = float(cooldown_s)
        self._clock = clock
        self._lock = threading.Lock()  # counters are shared by every loop and thread
        self._turn = 0  # rotates ties so equal replicas share evenly

    @property
    def identity(self) -> str:
        """The deployment, for the cache key: replica identities sorted, comma-joined."""
        return ",".join(sorted(r.identity for r in self.replicas))

    def describe(self) -> str:
        """The replicas for messages (credentials removed)."""
        return ", ".join(r.identity for r in self.replicas)

    def __len__(self) -> int:
        return len(self.replicas)

    def pick(self, tried: set[int]) -> int | None:
        """Index of the replica for the next attempt, or None when no failover is left.

        First attempt: the healthy replica with the fewest requests in flight; when every
        replica is cooling down, the one whose cooldown ends first. Failover attempts only
        go to healthy replicas not tried yet.
        """
        now = self._clock()
        with self._lock:
            n = len(self.replicas)
            order = [(self._turn + k) % n for k in range(n)]
            fresh = [i for i in order if i not in tried]
            healthy = [i for i in fresh if self.replicas[i].cool_until <= now]
            if healthy:
                best = min(healthy, key=lambda i: self.replicas[i].outstanding)
            elif not tried and fresh:
                best = min(fresh, key=lambda i: self.replicas[i].cool_until)
            else:
                return None
            self._turn = (best + 1) % n
            self.replicas[best].outstanding += 1
            return best

    def _done(self, index: int, ok: bool, cool: bool) -> None:
        with self._lock:
            r = self.replicas[index]
            r.outstanding -= 1
            if ok:
                r.served += 1
                r.cool_until = 0.0
            elif cool:
                r.failures += 1
                r.cool_until = self._clock() + self.cooldown_s

    async def call(
        self,
        attempt: Callable[[Replica], Awaitable[T]],
        classify: Callable[[BaseException], ErrorInfo | None],
        timeout_s: float | None,
    ) -> T:
        """One logical call: `attempt(replica)` on replicas in turn until one answers.

        Each attempt runs under its own `timeout_s`. Raises the last failure (for the
        shared retry loop to classify) when every replica it may try has failed, and any
        failure that is not the replica's fault at once.
        """
        tried: set[int] = set()
        while True:
            index = self.pick(tried)
            if index is None:  # unreachable: a first pick always finds a replica
                raise RuntimeError(f"{self.label}: no replica to try")
            tried.add(index)
            replica = self.replicas[index]
            try:
                if timeout_s is None:
                    result = await attempt(replica)
                else:
                    result = await asyncio.wait_for(attempt(replica), timeout=timeout_s)
            except asyncio.CancelledError:
                self._done(index, ok=False, cool=False)
                raise
            except Exception as exc:
                info = _failover_info(exc, classify, timeout_s)
                self._done(index, ok=False, cool=info is not None)
                if info is None:
                    raise
                if len(tried) >= len(self.replicas) or not self._any_healthy(tried):
                    raise
                log.warning(
                    "%s: replica %s failed (%s); cooled down %.0f s, trying another replica",
                    self.label,
                    replica.identity,
                    scrub_line(info.message, 200),
                    self.cooldown_s,
                )
                continue
            self._done(index, ok=True, cool=False)
            return result

    def _any_healthy(self, tried: set[int]) -> bool:
        now = self._clock()
        with self._lock:
            return any(r.cool_until <= now for i, r in enumerate(self.replicas) if i not in tried)


def _failover_info(
    exc: BaseException,
    classify: Callable[[BaseException], ErrorInfo | None],
    timeout_s: float | None,
) -> ErrorInfo | None:
    """The failure, when another replica might succeed where this one failed; else None."""
    if isinstance(exc, TimeoutError):
        within = f" within {timeout_s:g} s" if timeout_s is not None else ""
        return ErrorInfo(ErrorKind.transient, f"no answer{within}", group="timeout")
    info = classify(exc)
    if info is None or info.kind is ErrorKind.fatal:
        return None
    return info
