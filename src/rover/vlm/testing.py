"""Loopback servers that speak enough of the OpenAI and Gemini REST APIs for offline tests.

They let tests (ours and anyone's) drive the *real* SDK code paths — HTTP, JSON, errors,
retries — without a network or a key. Each runs a stdlib threaded HTTP server on
127.0.0.1 with a random port, records every request it receives (JSON body plus headers,
minus credentials), and answers from a script of `Reply`s, then from an `answer` function::

    with OpenAICompatServer() as server:
        server.answer = lambda body: "Frame description: ..."
        server.script(Reply(status=429, headers={"retry-after": "0"}))  # first call: 429
        vlm = load_vlm(f"openai:test-model@{server.base_url}", config)

Like a real provider, both honour the request's output limit (`max_tokens` /
`max_completion_tokens`, Gemini `maxOutputTokens`): an answer longer than that many words
(the servers count a word as a token) is cut and reported with finish reason "length" /
"MAX_TOKENS", so the truncation handling of the methods runs against real HTTP.

Test helpers only: nothing in rover imports this module.
"""

from __future__ import annotations

import json
import re
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any

_CREDENTIAL_HEADERS = {"authorization", "x-goog-api-key", "api-key"}


@dataclass
class Reply:
    """One scripted response.

    Attributes:
        status: HTTP status; non-200 sends the provider's error JSON with `text` as message.
        text: answer text (200) or error message; None = ask the server's `answer` function.
        headers: extra response headers (e.g. {"retry-after": "1"}).
        delay_s: sleep this long before answering (to trigger client timeouts).
        usage: (prompt, completion) tokens to report; None = a default; False = report none.
        code: provider error code (e.g. "insufficient_quota").
        raw: send these exact bytes as the body instead (hostile or malformed replies).
        content_type: the content-type header sent with the body.
        cached_tokens: prompt tokens to report as served from the provider's prefix cache
            (OpenAI/vLLM `prompt_tokens_details.cached_tokens`, Gemini
            `cachedContentTokenCount`); None = report no such field.
    """

    status: int = 200
    text: str | None = None
    headers: dict[str, str] = field(default_factory=dict)
    delay_s: float = 0.0
    usage: tuple[int, int] | bool | None = None
    code: str | None = None
    raw: bytes | None = None
    content_type: str = "application/json"
    cached_tokens: int | None = None


class _LoopbackServer:
    """Threaded HTTP server on 127.0.0.1 recording requests and replaying a script."""

    def __init__(self) -> None:
        self.requests: list[dict[str, Any]] = []
        self.keys_seen: list[str] = []  # credentials received (kept apart from `requests`)
        self.in_flight = 0
        self.max_in_flight = 0  # most requests being handled at once (concurrency checks)
        self.answer: Callable[[dict[str, Any]], str] = lambda body: "ok"
        self._script: deque[Reply] = deque()
        self._lock = threading.Lock()
        outer = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: Any) -> None:  # keep test output clean
                pass

            def do_POST(self) -> None:
                outer._handle(self)

            def do_GET(self) -> None:
                outer._handle(self)

        self._httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._httpd.daemon_threads = True
        self._httpd.block_on_close = False
        self.port = self._httpd.server_address[1]
        self._thread = threading.Thread(
            target=self._httpd.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True
        )
        self._thread.start()

    # --- scripting ---------------------------------------------------------------------

    def script(self, *replies: Reply) -> None:
        """Queue replies for the next requests, in order (then `answer` takes over)."""
        with self._lock:
            self._script.extend(replies)

    @property
    def count(self) -> int:
        with self._lock:
            return len(self.requests)

    def close(self) -> None:
        self._httpd.shutdown()
        self._httpd.server_close()

    def __enter__(self) -> _LoopbackServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # --- request handling --------------------------------------------------------------

    def _handle(self, h: BaseHTTPRequestHandler) -> None:
        length = int(h.headers.get("content-length") or 0)
        raw = h.rfile.read(length) if length else b""
        try:
            body = json.loads(raw) if raw else {}
        except json.JSONDecodeError:
            body = {"_raw": raw.decode("utf-8", "replace")}
        headers = {k.lower(): v for k, v in h.headers.items()}
        with self._lock:
            for name in _CREDENTIAL_HEADERS & headers.keys():
                self.keys_seen.append(headers.pop(name))
            record = dict(body) if isinstance(body, dict) else {"_body": body}
            record["_path"] = h.path
            record["_headers"] = headers
            self.requests.append(record)
            reply = self._script.popleft() if self._script else Reply()
            self.in_flight += 1
            self.max_in_flight = max(self.max_in_flight, self.in_flight)
        try:
            if reply.delay_s:
                time.sleep(reply.delay_s)
            status, payload = self._respond(h.path, body, reply)
        finally:
            with self._lock:
                self.in_flight -= 1
        data = reply.raw if reply.raw is not None else json.dumps(payload).encode()
        try:
            h.send_response(status)
            h.send_header("content-type", reply.content_type)
            h.send_header("content-length", str(len(data)))
            for k, v in reply.headers.items():
                h.send_header(k, v)
            h.end_headers()
            h.wfile.write(data)
        except (BrokenPipeError, ConnectionResetError):  # the client gave up (timeout test)
            pass

    def _respond(self, path: str, body: Any, reply: Reply) -> tuple[int, dict[str, Any]]:
        raise NotImplementedError


def cut_words(text: str, limit: Any) -> tuple[str, bool]:
    """`text` cut after `limit` whitespace-separated words (formatting kept), and if it was."""
    if not isinstance(limit, int) or isinstance(limit, bool) or limit <= 0:
        return text, False
    for i, m in enumerate(re.finditer(r"\S+", text), start=1):
        if i == limit:
            return text[: m.end()], text[m.end() :].strip() != ""
    return text, False


def _count_images(obj: Any) -> int:
    """Image parts in a request body (OpenAI `image_url` or Gemini inline data)."""
    if isinstance(obj, dict):
        own = int(any(k in obj for k in ("image_url", "inline_data", "inlineData")))
        return own + sum(_count_images(v) for v in obj.values())
    if isinstance(obj, list):
        return sum(_count_images(v) for v in obj)
    return 0


class OpenAICompatServer(_LoopbackServer):
    """`POST /v1/chat/completions` and `GET /v1/models`, like vLLM or Ollama would answer."""

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.port}/v1"

    def _respond(self, path: str, body: Any, reply: Reply) -> tuple[int, dict[str, Any]]:
        if reply.status != 200:
            error = {"message": reply.text or "error", "type": "test_error", "code": reply.code}
            return reply.status, {"error": error}
        if path.rstrip("/").endswith("/models"):
            return 200, {"object": "list", "data": [{"id": "test-model", "object": "model"}]}
        if not path.rstrip("/").endswith("/chat/completions"):
            return 404, {"error": {"message": f"no route {path}", "type": "not_found"}}
        text = reply.text if reply.text is not None else self.answer(body)
        limit = body.get("max_completion_tokens") or body.get("max_tokens")
        text, cut = cut_words(text, limit)
        out: dict[str, Any] = {
            "id": f"chatcmpl-{self.count}",
            "object": "chat.completion",
            "created": int(time.time()),
            "model": body.get("model", ""),
            "choices": [
                {
                    "index": 0,
                    "message": {"role": "assistant", "content": text},
                    "finish_reason": "length" if cut else "stop",
                }
            ],
        }
        if reply.usage is not False:
            p, c = (
                reply.usage
                if isinstance(reply.usage, tuple)
                else (40 + 100 * _count_images(body), len(text.split()))
            )
            out["usage"] = {"prompt_tokens": p, "completion_tokens": c, "total_tokens": p + c}
            if reply.cached_tokens is not None:
                out["usage"]["prompt_tokens_details"] = {"cached_tokens": reply.cached_tokens}
        return 200, out


_GEMINI_PATH = re.compile(r"^/(v1beta|v1)/models/(?P<model>[^/:]+):generateContent")


class GeminiRESTServer(_LoopbackServer):
    """`POST /v1beta/models/<model>:generateContent`, answering like the Gemini API."""

    @property
    def base_url(self) -> str:
        return f"http://127.0.0.1:{self.port}"

    def _respond(self, path: str, body: Any, reply: Reply) -> tuple[int, dict[str, Any]]:
        match = _GEMINI_PATH.match(path)
        if reply.status != 200:
            status = {400: "INVALID_ARGUMENT", 401: "UNAUTHENTICATED", 403: "PERMISSION_DENIED"}
            status |= {404: "NOT_FOUND", 429: "RESOURCE_EXHAUSTED", 500: "INTERNAL"}
            error = {
                "code": reply.status,
                "message": reply.text or "error",
                "status": status.get(reply.status, "UNAVAILABLE"),
            }
            return reply.status, {"error": error}
        if match is None:
            return 404, {
                "error": {"code": 404, "message": f"no route {path}", "status": "NOT_FOUND"}
            }
        text = reply.text if reply.text is not None else self.answer(body)
        config = body.get("generationConfig") or body.get("generation_config") or {}
        limit = config.get("maxOutputTokens") or config.get("max_output_tokens")
        text, cut = cut_words(text, limit)
        finish = "MAX_TOKENS" if cut else "STOP"
        out: dict[str, Any] = {
            "candidates": [
                {"content": {"role": "model", "parts": [{"text": text}]}, "finishReason": finish}
            ],
            "modelVersion": match.group("model"),
        }
        if reply.usage is not False:
            images = _count_images(body)
            p, c = (
                reply.usage
                if isinstance(reply.usage, tuple)
                else (30 + 258 * images, len(text.split()))
            )
            details = [{"modality": "TEXT", "tokenCount": p - 258 * images}]
            if images:
                details.append({"modality": "IMAGE", "tokenCount": 258 * images})
            out["usageMetadata"] = {
                "promptTokenCount": p,
                "candidatesTokenCount": c,
                "totalTokenCount": p + c,
                "promptTokensDetails": details,
            }
            if reply.cached_tokens is not None:
                out["usageMetadata"]["cachedContentTokenCount"] = reply.cached_tokens
        return 200, out
