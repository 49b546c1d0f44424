"""`openai:<model>[@<base_url>]`: GPT-4o/5 and every OpenAI-compatible server.

Uses the official SDK's AsyncOpenAI client and Chat Completions, with images as base64
data URLs. The same code serves vLLM, SGLang, Ollama, LM Studio and Gemini's
OpenAI-compatible endpoint: only the base URL (and which variable holds the key) differ.
The SDK's own retries are off (`max_retries=0`): our shared loop retries instead.
"""

from __future__ import annotations

import base64
import os
from typing import Any

from rover.errors import BackendError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.keys import install_log_scrubbing, read_key
from rover.vlm.retry import ErrorInfo, ErrorKind, parse_retry_after
from rover.vlm.tokens import estimate_prompt_tokens
from rover.vlm.types import ImagePart, Message, Prompt, SamplingParams, TextPart, Usage

DEFAULT_KEY_ENV = "OPENAI_API_KEY"
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
        self.base_url = base_url or self.config.base_url or os.environ.get("OPENAI_BASE_URL")
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
        where = f" @ {self.base_url}" if self.base_url else ""
        return f"<OpenAIBackend {self.model}{where}>"

    def cache_extra(self) -> dict[str, Any]:
        return {"detail": self.config.detail}

    def _client(self) -> Any:
        def make() -> Any:
            from openai import AsyncOpenAI

            return AsyncOpenAI(
                api_key=self._key,
                base_url=self.base_url,
                max_retries=0,
                timeout=self.config.timeout_s,
            )

        return self.loop_local("client", make)

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
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
        response = await self._client().chat.completions.create(**kwargs)
        text = ""
        if response.choices:
            text = response.choices[0].message.content or ""
        usage = None
        if response.usage is not None and response.usage.prompt_tokens:
            # the API does not break images out; the image part is the published rule's share
            _, image_tokens = estimate_prompt_tokens(prompt, self.token_rule)
            usage = Usage(
                prompt_tokens=response.usage.prompt_tokens,
                completion_tokens=response.usage.completion_tokens or 0,
                image_tokens=min(image_tokens, response.usage.prompt_tokens),
                source="reported",
            )
        return RawAnswer(text=text, usage=usage)

    def _classify(self, exc: BaseException) -> ErrorInfo | None:
        import openai

        if isinstance(exc, openai.APITimeoutError):
            return ErrorInfo(ErrorKind.transient, "request timed out")
        if isinstance(exc, openai.APIConnectionError):
            where = self.base_url or "api.openai.com"
            return ErrorInfo(ErrorKind.transient, f"cannot connect to {where}")
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
            where = self.base_url or "api.openai.com"
            return ErrorInfo(
                ErrorKind.fatal,
                f"not found (HTTP 404) at {where}: is the model name right? {detail}",
            )
        return ErrorInfo(ErrorKind.fatal, f"request rejected (HTTP {status}): {detail}")


def _short_message(exc: Any) -> str:
    """The server's error message on one line, bounded in length."""
    body = getattr(exc, "body", None)
    message = None
    if isinstance(body, dict):
        err = body.get("error", body)
        message = err.get("message") if isinstance(err, dict) else str(err)
    message = message or getattr(exc, "message", "") or type(exc).__name__
    return " ".join(str(message).split())[:300]
