"""`gemini:<model>[@<base_url>]`: Google's Gemini API through `google-genai` (the current SDK).

Images go inline as bytes; system messages become the system instruction; usage comes
from `usage_metadata`, including the image share when the API breaks it out by modality.
The SDK's own retries are off (one attempt): our shared loop retries instead.
"""

from __future__ import annotations

import re
from typing import Any

from rover.errors import BackendError, InputError, MissingExtraError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.endpoint import check_base_url, endpoint_identity
from rover.vlm.keys import install_log_scrubbing, read_key, register_url_secret
from rover.vlm.retry import ErrorInfo, ErrorKind, MalformedReply, parse_retry_after
from rover.vlm.scrub import scrub_line
from rover.vlm.tokens import estimate_prompt_tokens
from rover.vlm.types import Prompt, SamplingParams, TextPart, Usage

DEFAULT_KEY_ENVS = ("GEMINI_API_KEY", "GOOGLE_API_KEY")
DEFAULT_BASE_URL = "https://generativelanguage.googleapis.com"
UNREACHABLE_RETRIES = 2  # retries when the endpoint cannot be reached at all


def _import_genai() -> Any:
    try:
        from google import genai
    except ImportError as exc:
        raise MissingExtraError("google-genai", "gemini", "the gemini backend") from exc
    return genai


class GeminiBackend(BaseBackend):
    backend = "gemini"

    def __init__(
        self, model: str, base_url: str | None = None, config: BackendConfig | None = None
    ) -> None:
        super().__init__(model, config)
        _import_genai()
        install_log_scrubbing()
        given = base_url or self.config.base_url
        if isinstance(given, list | tuple) or (isinstance(given, str) and "," in given):
            raise InputError(
                f"gemini:{model}: endpoint pools (several base URLs) are for "
                "OpenAI-compatible servers (openai:<model>@<url>,<url>)"
            )
        self.base_url = given or None
        if self.base_url is not None:
            self.base_url = check_base_url(self.base_url, f"gemini:{model}")
            register_url_secret(self.base_url)
        names = (self.config.api_key_env,) if self.config.api_key_env else DEFAULT_KEY_ENVS
        key, _ = read_key(*names)
        if key is None:
            raise BackendError(
                f"gemini:{model}: no API key: set {' or '.join(names)} "
                "(or name another variable with --api-key-env)"
            )
        self._key = key
        self.key_env = " / ".join(names)

    def __repr__(self) -> str:  # never show the key
        return f"<GeminiBackend {self.model}>"

    def endpoint(self) -> str:
        return endpoint_identity(self.base_url or DEFAULT_BASE_URL)

    def _prepare(self) -> None:
        _ = self._client().aio.models  # this loop's client, before the first timed attempt

    def _client(self) -> Any:
        def make() -> Any:
            genai = _import_genai()
            from google.genai import types

            http = types.HttpOptions(
                base_url=self.base_url,
                api_version="v1beta",  # the Gemini API's current REST version
                timeout=int(self.config.timeout_s * 1000),
                retry_options=types.HttpRetryOptions(attempts=1),
            )
            return genai.Client(api_key=self._key, vertexai=False, http_options=http)

        return self.loop_local("client", make)

    def _contents(self, prompt: Prompt) -> tuple[str | None, list[Any]]:
        from google.genai import types

        system: list[str] = []
        contents: list[Any] = []
        for message in prompt.messages:
            parts = message.parts()
            if message.role == "system":
                system.extend(p.text for p in parts if isinstance(p, TextPart))
                continue
            converted = [
                types.Part.from_text(text=p.text)
                if isinstance(p, TextPart)
                else types.Part.from_bytes(data=p.image.data, mime_type=p.image.mime)
                for p in parts
            ]
            role = "model" if message.role == "assistant" else "user"
            contents.append(types.Content(role=role, parts=converted))
        return ("\n".join(system) if system else None), contents

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        from google.genai import types

        system, contents = self._contents(prompt)
        config = types.GenerateContentConfig(
            system_instruction=system,
            temperature=params.temperature,
            max_output_tokens=params.max_tokens,
            seed=params.seed,
            automatic_function_calling=types.AutomaticFunctionCallingConfig(disable=True),
        )
        response = await self._client().aio.models.generate_content(
            model=self.model, contents=contents, config=config
        )
        if response is None or isinstance(response, str | bytes | list | dict):
            raise MalformedReply("expected a generateContent response object")
        text = _response_text(response)
        try:
            usage = self._usage(prompt, response)
        except (TypeError, ValueError, AttributeError):  # counts that are not counts
            usage = None
        finish = _finish_reason(response)
        return RawAnswer(
            text=text, usage=usage, finish_reason=finish, truncated=finish == "MAX_TOKENS"
        )

    def _usage(self, prompt: Prompt, response: Any) -> Usage | None:
        meta = getattr(response, "usage_metadata", None)
        if meta is None or not meta.prompt_token_count:
            return None
        completion = (meta.candidates_token_count or 0) + (meta.thoughts_token_count or 0)
        image_tokens = sum(
            d.token_count or 0
            for d in (meta.prompt_tokens_details or [])
            if str(getattr(d.modality, "value", d.modality)).upper() == "IMAGE"
        )
        if not image_tokens:
            _, image_tokens = estimate_prompt_tokens(prompt, self.token_rule)
            image_tokens = min(image_tokens, meta.prompt_token_count)
        return Usage(
            prompt_tokens=meta.prompt_token_count,
            completion_tokens=completion,
            image_tokens=image_tokens,
            source="reported",
            cached_prompt_tokens=_cached_count(meta),
        )

    def _classify(self, exc: BaseException) -> ErrorInfo | None:
        from google.genai import errors

        if isinstance(exc, errors.APIError):
            return self._classify_status(exc)
        module = type(exc).__module__
        name = type(exc).__name__
        if "Timeout" in name:
            return ErrorInfo(
                ErrorKind.transient,
                f"no answer within {self.config.timeout_s:g} s (raise it with --timeout)",
                group="timeout",
            )
        if isinstance(exc, OSError) or module.startswith(("httpx", "httpcore", "aiohttp")):
            return ErrorInfo(
                ErrorKind.transient,
                f"cannot connect to {self.endpoint()} ({name})",
                retry_limit=UNREACHABLE_RETRIES,
                group="connect",
            )
        if module.startswith("pydantic") and name == "ValidationError":
            return ErrorInfo(
                ErrorKind.transient,
                "malformed response from the server: unexpected body shape",
                retry_limit=2,
                group="malformed",
            )
        return None

    def _classify_status(self, exc: Any) -> ErrorInfo:
        code = int(exc.code or 0)
        detail = scrub_line(str(exc.message or exc.status or ""), 300)  # scrub, then cut
        headers = getattr(getattr(exc, "response", None), "headers", None)
        retry_after = parse_retry_after(headers) or _retry_delay(exc.details)
        if code == 429:
            return ErrorInfo(
                ErrorKind.rate_limit, f"rate limited (HTTP 429): {detail}", retry_after
            )
        if code in (408, 409) or code >= 500:
            return ErrorInfo(
                ErrorKind.transient, f"server error (HTTP {code}): {detail}", retry_after
            )
        if code in (401, 403) or (code == 400 and "API key" in detail):
            return ErrorInfo(
                ErrorKind.fatal,
                f"authentication failed (HTTP {code}): check the key in ${self.key_env}: {detail}",
            )
        if code == 404:
            return ErrorInfo(
                ErrorKind.fatal, f"not found (HTTP 404): is the model name right? {detail}"
            )
        return ErrorInfo(ErrorKind.fatal, f"request rejected (HTTP {code}): {detail}")


def _cached_count(meta: Any) -> int:
    """`usage_metadata.cached_content_token_count` (implicit or explicit context caching),
    bounded by the prompt; 0 when absent or not a count."""
    cached = getattr(meta, "cached_content_token_count", None)
    if not isinstance(cached, int) or isinstance(cached, bool) or cached < 0:
        return 0
    return min(cached, meta.prompt_token_count)


def _finish_reason(response: Any) -> str | None:
    """The first candidate's finish reason by name ("STOP", "MAX_TOKENS"), if any."""
    for candidate in (getattr(response, "candidates", None) or [])[:1]:
        reason = getattr(candidate, "finish_reason", None)
        if reason is not None:
            return str(getattr(reason, "name", None) or getattr(reason, "value", reason))
    return None


def _response_text(response: Any) -> str:
    """The answer's text parts joined; empty when the model returned none (e.g. blocked)."""
    texts: list[str] = []
    for candidate in (getattr(response, "candidates", None) or [])[:1]:
        content = getattr(candidate, "content", None)
        for part in getattr(content, "parts", None) or []:
            if getattr(part, "text", None) and not getattr(part, "thought", False):
                texts.append(part.text)
    return "".join(texts)


def _retry_delay(details: Any) -> float | None:
    """`RetryInfo.retryDelay` ("12s") from a Google error body, if present."""
    match = re.search(r"retryDelay['\"]?\s*:\s*['\"]([\d.]+)s", str(details))
    return float(match.group(1)) if match else None
