"""The shared backend machinery: cache, concurrency limit, retries, usage accounting.

A provider subclasses `BaseBackend` and writes two things: `_generate` (convert our
prompt to its SDK's format, make one call, return text and reported usage) and `_classify`
(what kind of failure an SDK exception is). Everything else happens here, once.
"""

from __future__ import annotations

import asyncio
import time
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, TypeVar

from rover.vlm.cache import ResponseCache, cache_key
from rover.vlm.config import BackendConfig, TokenRule
from rover.vlm.retry import ErrorInfo, RetryPolicy, call_with_retries, classify_common
from rover.vlm.scrub import scrub
from rover.vlm.tokens import default_rule, estimate_usage
from rover.vlm.types import Completion, ImageEncoding, Prompt, SamplingParams, Usage

if TYPE_CHECKING:
    from rover.episode import Episode

R = TypeVar("R")


@dataclass
class RawAnswer:
    """What one provider call returned, before caching and accounting."""

    text: str
    usage: Usage | None = None  # None: the provider reported nothing, estimate it
    finish_reason: str | None = None  # the provider's stop reason, as it wrote it
    truncated: bool = False  # stopped at max_tokens ("length", "MAX_TOKENS")


class BaseBackend:
    """A VLM backend: `await complete(prompt)` with everything a real API needs around it."""

    backend: str = "base"
    use_cache: ClassVar[bool] = True  # oracle and replay answers are free: never cached

    def __init__(self, model: str, config: BackendConfig | None = None) -> None:
        self.model = model
        self.config = config or BackendConfig()
        self._cache: ResponseCache | None = None
        # per event loop: asyncio primitives and HTTP clients are bound to the loop that
        # created them, and callers may use one VLM from successive asyncio.run calls
        self._per_loop: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, dict[str, Any]] = (
            weakref.WeakKeyDictionary()
        )

    # --- what subclasses provide -------------------------------------------------------

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        raise NotImplementedError

    def _classify(self, exc: BaseException) -> ErrorInfo | None:
        """The kind of failure `exc` is; None lets it propagate (not an API error)."""
        return None

    def _prepare(self) -> None:
        """Set up what calls in this event loop share (HTTP clients), before the first
        timed attempt: building a client and the SDK's lazy imports take seconds on a busy
        CPU and must not eat into a call's timeout."""

    def cache_extra(self) -> dict[str, Any]:
        """Backend settings that change answers and so belong in the cache key."""
        return {}

    def endpoint(self) -> str:
        """Which server answers (its URL without credentials); part of the cache key, so two
        deployments serving the same model name never share answers."""
        return ""

    # --- public interface --------------------------------------------------------------

    @property
    def image_encoding(self) -> ImageEncoding:
        """How prompt images should be encoded for this backend (from the config)."""
        return self.config.image_encoding()

    @property
    def token_rule(self) -> TokenRule:
        return self.config.token_rule or default_rule(self.backend, self.config.detail)

    @property
    def spec(self) -> str:
        return f"{self.backend}:{self.model}"

    def bind(self, episode: Episode) -> BaseBackend:
        """Real backends answer from pixels alone, so every episode uses the same instance."""
        return self

    def default_params(self) -> SamplingParams:
        return self.config.sampling()

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        """Answer `prompt`: from the cache if seen before, else via the provider with retries."""
        params = params or self.default_params()
        cache = self._response_cache()
        key = ""
        if cache is not None:
            key = cache_key(
                self.backend,
                self.model,
                prompt.fingerprint(),
                params,
                self.cache_extra(),
                endpoint=self.endpoint(),
            )
            hit = cache.get(key)
            if hit is not None:
                return hit
        async with self._semaphore():
            self._prepare()
            start = time.perf_counter()
            raw = await call_with_retries(
                lambda: self._generate(prompt, params),
                self._classify_any,
                self._retry_policy(),
                self.spec,
            )
            latency = time.perf_counter() - start
        # a server may echo a key or credentials in its answer: scrub before it is cached,
        # recorded, parsed into a trace or shown
        text = scrub(raw.text)
        usage = raw.usage or estimate_usage(prompt, text, self.token_rule)
        completion = Completion(
            text=text,
            usage=usage,
            latency_s=latency,
            cached=False,
            backend=self.backend,
            model=self.model,
            finish_reason=raw.finish_reason,
            truncated=raw.truncated,
        )
        if cache is not None:
            cache.put(key, completion)
        return completion

    async def aclose(self) -> None:
        """Release resources held for the running event loop (HTTP clients)."""
        state = self._per_loop.pop(asyncio.get_running_loop(), {})
        for value in state.values():
            close = getattr(value, "aclose", None) or getattr(value, "close", None)
            if close is not None and not isinstance(value, asyncio.Semaphore):
                result = close()
                if asyncio.iscoroutine(result):
                    await result

    # --- helpers -----------------------------------------------------------------------

    def _retry_policy(self) -> RetryPolicy:
        c = self.config
        return RetryPolicy(
            max_retries=c.max_retries,
            timeout_s=c.timeout_s,
            base_wait_s=c.retry_base_wait_s,
            max_wait_s=c.retry_max_wait_s,
            timeout_retries=c.timeout_retries,
        )

    def _classify_any(self, exc: BaseException) -> ErrorInfo | None:
        """The provider's verdict, else the shared one for unreadable bodies."""
        return self._classify(exc) or classify_common(exc)

    def _response_cache(self) -> ResponseCache | None:
        if not self.use_cache or self.config.no_cache:
            return None
        if self._cache is None:
            self._cache = ResponseCache(self.config.resolved_cache_path())
        return self._cache

    def loop_local(self, name: str, factory: Callable[[], R]) -> R:
        """A per-event-loop object (client, semaphore), created on first use in that loop."""
        state = self._per_loop.setdefault(asyncio.get_running_loop(), {})
        if name not in state:
            state[name] = factory()
        return state[name]

    def _semaphore(self) -> asyncio.Semaphore:
        return self.loop_local("semaphore", lambda: asyncio.Semaphore(self.config.concurrency))

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.spec}>"
