"""`openai:<model>[@<base_url>]`: GPT-4o/5 and every OpenAI-compatible server.

Uses the official SDK's AsyncOpenAI client and Chat Completions, with images as base64
data URLs. The same code serves vLLM, SGLang, Ollama, LM Studio and Gemini's
OpenAI-compatible endpoint: only the base URL (and which variable holds the key) differ.
The SDK's own retries are off (`max_retries=0`): our shared loop retries instead.
"""

from __future__ import annotations

import base64
import dataclasses
import os
from typing import Any

from rover.errors import BackendError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.endpoint import check_base_url, endpoint_identity
from rover.vlm.keys import install_log_scrubbing, read_key, register_url_secret
from rover.vlm.pool import EndpointPool, Replica, split_urls
from rover.vlm.retry import ErrorInfo, ErrorKind, MalformedReply, RetryPolicy, parse_retry_after
from rover.vlm.scrub import scrub_line
from rover.vlm.tokens import estimate_prompt_tokens
from rover.vlm.types import ImagePart, Message, Prompt, SamplingParams, TextPart, Usage

DEFAULT_KEY_ENV = "OPENAI_API_KEY"
# retries when the endpoint cannot be reached at all (refused, DNS): fail in seconds
UNREACHABLE_RETRIES = 2
# servers run without auth still need a non-empty key for the SDK
PLACEHOLDER_KEY = "not-needed"
# reasoning models take max_completion_tokens and only their default temperature
_REASONING_PREFIXES = ("gpt-5", "o1", "o3", "o4")


def _is_reasoning_model(model: str) -> bool:
    return model.lower().startswith(_REASONING_PREFIXES)


def _data_url(part: ImagePart) -> str:
    return f"data:{part.image.mime};base64,{base64.b64encode(part.image.data).decode('ascii')}"


def to_openai_messages(prompt: Prompt, default_detail: str) -> list[dict[str, Any]]:
    """Our prompt as Chat Completions messages (text-only messages become plain strings)."""
    out: list[dict[str, Any]] = []
    for message in prompt.messages:
        out.append(_convert_message(message, default_detail))
    return out


def _convert_message(message: Message, default_detail: str) -> dict[str, Any]:
    parts = message.parts()
    if message.role != "user" or all(isinstance(p, TextPart) for p in parts):
        # system and assistant content is text only in the API
        text = "\n".join(p.text for p in parts if isinstance(p, TextPart))
        return {"role": message.role, "content": text}
    content: list[dict[str, Any]] = []
    for p in parts:
        if isinstance(p, TextPart):
            content.append({"type": "text", "text": p.text})
        else:
            content.append(
                {
                    "type": "image_url",
                    "image_url": {"url": _data_url(p), "detail": p.detail or default_detail},
                }
            )
    return {"role": "user", "content": content}


class OpenAIBackend(BaseBackend):
    backend = "openai"

    def __init__(
        self, model: str, base_url: str | None = None, config: BackendConfig | None = None
    ) -> None:
        super().__init__(model, config)
        try:
            import openai  # noqa: F401  (fail now, with an install hint, not at the first call)
        except ImportError as exc:  # a core dependency, so there is no extra to name
            raise BackendError(
                "the openai backend needs the 'openai' package: pip install 'openai>=1.40'"
            ) from exc
        install_log_scrubbing()
        # OPENAI_BASE_URL is the SDK's own override; honour it here too so the key rule matches
        urls = split_urls(base_url or self.config.base_url or os.environ.get("OPENAI_BASE_URL"))
        # several URLs: replicas of one model, routed and failed over by the pool
        self.pool: EndpointPool | None = None
        self.base_url: str | None = None
        if len(urls) > 1:
            self.pool = EndpointPool(urls, f"openai:{model}", self.config.pool_cooldown_s)
            self.base_url = self.pool.replicas[0].url
        elif urls:
            self.base_url = check_base_url(urls[0], f"openai:{model}")
        for url in urls:
            register_url_secret(url)
        env = self.config.api_key_env or DEFAULT_KEY_ENV
        key, _ = read_key(env)
        if key is None:
            if self.base_url is None:
                raise BackendError(
                    f"openai:{model}: no API key: set {env} (or name another variable with "
                    "--api-key-env), or point at a local server with openai:<model>@<url>"
                )
            key = PLACEHOLDER_KEY
        self._key = key
        self.key_env = env

    def __repr__(self) -> str:  # never show the key
        where = f" @ {self.where}" if self.base_url else ""
        return f"<OpenAIBackend {self.model}{where}>"

    @property
    def where(self) -> str:
        """The server, as shown in messages (credentials removed)."""
        if self.pool is not None:
            return f"the pool ({self.pool.describe()})"
        return endpoint_identity(self.base_url) if self.base_url else "api.openai.com"

    def cache_extra(self) -> dict[str, Any]:
        return {"detail": self.config.detail}

    def endpoint(self) -> str:
        if self.pool is not None:  # one deployment, whichever replica answers
            return self.pool.identity
        return endpoint_identity(self.base_url or "https://api.openai.com/v1")

    def _retry_policy(self) -> RetryPolicy:
        policy = super()._retry_policy()
        if self.pool is None:
            return policy
        # the pool times each replica's attempt itself, so a failover gets a fresh timeout
        return dataclasses.replace(policy, wrap_timeout=False)

    def _prepare(self) -> None:
        # every replica's client for this loop, its chat resource imported (lazily, by the SDK)
        urls = [r.url for r in self.pool.replicas] if self.pool is not None else [self.base_url]
        for url in urls:
            _ = self._client(url).chat.completions

    def _client(self, base_url: str | None = None) -> Any:
        url = base_url or self.base_url

        def make() -> Any:
            import httpx
            from openai import AsyncOpenAI

            c = self.config
            return AsyncOpenAI(
                api_key=self._key,
                base_url=url,
                max_retries=0,
                timeout=httpx.Timeout(c.timeout_s, connect=min(c.connect_timeout_s, c.timeout_s)),
            )

        name = "client" if url == self.base_url else f"client:{endpoint_identity(url or '')}"
        return self.loop_local(name, make)

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        if self.pool is None:
            return await self._generate_at(None, prompt, params)

        async def at(replica: Replica) -> RawAnswer:
            return await self._generate_at(replica.url, prompt, params)

        return await self.pool.call(at, self._classify_any, self.config.timeout_s)

    async def _generate_at(
        self, base_url: str | None, prompt: Prompt, params: SamplingParams
    ) -> RawAnswer:
        kwargs: dict[str, Any] = {
            "model": self.model,
            "messages": to_openai_messages(prompt, self.config.detail),
        }
        if _is_reasoning_model(self.model):
            kwargs["max_completion_tokens"] = params.max_tokens
        else:
            kwargs["max_tokens"] = params.max_tokens
            kwargs["temperature"] = params.temperature
        if params.seed is not None:
            kwargs["seed"] = params.seed
        response = await self._client(base_url).chat.completions.create(**kwargs)
        text = _reply_text(response)
        finish = _finish_reason(response)
        return RawAnswer(
            text=text,
            usage=self._usage(prompt, response),
            finish_reason=finish,
            truncated=finish == "length",
        )

    def _usage(self, prompt: Prompt, response: Any) -> Usage | None:
        """Reported usage, or None (estimate it) when absent or not a pair of counts."""
        reported = getattr(response, "usage", None)
        p = getattr(reported, "prompt_tokens", None)
        c = getattr(reported, "completion_tokens", None)
        if not isinstance(p, int) or isinstance(p, bool) or p <= 0:
            return None
        # the API does not break images out; the image part is the published rule's share
        _, image_tokens = estimate_prompt_tokens(prompt, self.token_rule)
        return Usage(
            prompt_tokens=p,
            completion_tokens=c if isinstance(c, int) and c >= 0 else 0,
            image_tokens=min(image_tokens, p),
            source="reported",
            cached_prompt_tokens=_cached_tokens(reported, p),
        )

    def _classify(self, exc: BaseException) -> ErrorInfo | None:
        import openai

        if isinstance(exc, openai.APITimeoutError):
            return ErrorInfo(
                ErrorKind.transient,
                f"no answer within {self.config.timeout_s:g} s (raise it with --timeout)",
                group="timeout",
            )
        if isinstance(exc, openai.APIConnectionError):
            return ErrorInfo(
                ErrorKind.transient,
                f"cannot connect to {self.where}",
                retry_limit=UNREACHABLE_RETRIES,
                group="connect",
            )
        if isinstance(exc, openai.APIStatusError):
            return self._classify_status(exc)
        if isinstance(exc, openai.APIResponseValidationError):
            return ErrorInfo(ErrorKind.transient, "malformed response from the server")
        return None

    def _classify_status(self, exc: Any) -> ErrorInfo:
        status = exc.status_code
        detail = _short_message(exc)
        if status == 429:
            if getattr(exc, "code", None) == "insufficient_quota":
                return ErrorInfo(ErrorKind.fatal, f"quota exhausted (HTTP 429): {detail}")
            return ErrorInfo(
                ErrorKind.rate_limit,
                f"rate limited (HTTP 429): {detail}",
                parse_retry_after(exc.response.headers),
            )
        if status in (408, 409) or status >= 500:
            return ErrorInfo(
                ErrorKind.transient,
                f"server error (HTTP {status}): {detail}",
                parse_retry_after(exc.response.headers),
            )
        if status in (401, 403):
            return ErrorInfo(
                ErrorKind.fatal,
                f"authentication failed (HTTP {status}): check the key in ${self.key_env}: "
                f"{detail}",
            )
        if status == 404:
            return ErrorInfo(
                ErrorKind.fatal,
                f"not found (HTTP 404) at {self.where}: is the model name right? {detail}",
            )
        return ErrorInfo(ErrorKind.fatal, f"request rejected (HTTP {status}): {detail}")


def _cached_tokens(reported: Any, prompt_tokens: int) -> int:
    """`usage.prompt_tokens_details.cached_tokens` (OpenAI; vLLM and SGLang with prefix
    caching on), bounded by the prompt; 0 when absent or not a count."""
    details = getattr(reported, "prompt_tokens_details", None)
    if isinstance(details, dict):  # an SDK that left an unknown shape as a plain dict
        cached = details.get("cached_tokens")
    else:
        cached = getattr(details, "cached_tokens", None)
    if not isinstance(cached, int) or isinstance(cached, bool) or cached < 0:
        return 0
    return min(cached, prompt_tokens)


def _short_message(exc: Any) -> str:
    """The server's error message on one line, bounded in length."""
    body = getattr(exc, "body", None)
    message = None
    if isinstance(body, dict):
        err = body.get("error", body)
        message = err.get("message") if isinstance(err, dict) else str(err)
    message = message or getattr(exc, "message", "") or type(exc).__name__
    return scrub_line(str(message), 300)  # scrubbed before the cut, never after


def _reply_text(response: Any) -> str:
    """The first choice's text; MalformedReply when the body is not a chat completion.

    A server that answers 200 with plain text, a JSON array, `null` or a choice without a
    message gets a bounded retry and then one line, instead of an AttributeError.
    """
    if isinstance(response, str | bytes | list | dict) or response is None:
        raise MalformedReply(f"expected a chat completion object, got {_kind(response)}")
    choices = getattr(response, "choices", None)
    if choices is None:
        raise MalformedReply("the body has no 'choices'")
    if isinstance(choices, list) and not choices:
        return ""  # a completion with no choices: an empty answer, parsed as such
    if not isinstance(choices, list):
        raise MalformedReply(f"'choices' is {_kind(choices)}, not a list")
    message = getattr(choices[0], "message", None)
    if message is None or isinstance(message, str | dict | list):
        raise MalformedReply("the first choice has no message object")
    content = getattr(message, "content", None)
    if content is None:
        return ""
    if not isinstance(content, str):
        raise MalformedReply(f"the message content is {_kind(content)}, not text")
    return content


def _kind(value: Any) -> str:
    return "null" if value is None else type(value).__name__


def _finish_reason(response: Any) -> str | None:
    """The first choice's finish reason ("stop", "length"), if the body gives a string."""
    choices = getattr(response, "choices", None)
    if not isinstance(choices, list) or not choices:
        return None
    reason = getattr(choices[0], "finish_reason", None)
    return reason if isinstance(reason, str) else None
