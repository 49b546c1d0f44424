"""API keys: read only from environment variables, and scrubbed from anything we print.

Every key this process reads is remembered (in memory only) so that `scrub` can remove it
from error messages and log records, whichever SDK produced them. Patterns for common key
shapes are scrubbed too, for keys we never read ourselves (e.g. echoed by a proxy).
"""

from __future__ import annotations

import logging
import os
import re
import threading

REDACTED = "<redacted>"

_KNOWN: set[str] = set()
_LOCK = threading.Lock()
# OpenAI-style (sk-...), Google API keys (AIza...), bearer tokens in echoed headers
_PATTERNS = re.compile(
    r"(\bsk-[A-Za-z0-9_\-]{8,}|\bAIza[0-9A-Za-z_\-]{20,}|\b(?i:bearer)\s+[A-Za-z0-9._\-]{8,})"
)
# loggers of the HTTP stacks the SDKs use; filters are not inherited, so name them all
_SDK_LOGGERS = (
    "openai",
    "openai._base_client",
    "httpx",
    "httpx2",
    "httpcore",
    "httpcore.http11",
    "httpcore.connection",
    "httpcore2.http11",
    "httpcore2.connection",
    "google_genai",
    "google_genai._api_client",
    "google_genai.models",
    "rover.vlm",
)


def register_secret(value: str) -> None:
    """Remember a secret so `scrub` removes it; short values are ignored (too many false hits)."""
    if value and len(value) >= 6:
        with _LOCK:
            _KNOWN.add(value)


def read_key(*names: str) -> tuple[str | None, str | None]:
    """The first non-empty environment variable among `names`: (value, name) or (None, None)."""
    for name in names:
        value = os.environ.get(name)
        if value:
            register_secret(value)
            return value, name
    return None, None


def scrub(text: str) -> str:
    """`text` with every known secret and key-shaped string replaced by <redacted>."""
    with _LOCK:
        known = sorted(_KNOWN, key=len, reverse=True)
    for secret in known:
        text = text.replace(secret, REDACTED)
    return _PATTERNS.sub(REDACTED, text)


class ScrubFilter(logging.Filter):
    """Rewrites a log record's message with secrets scrubbed (never drops the record)."""

    def filter(self, record: logging.LogRecord) -> bool:
        try:
            message = record.getMessage()
        except Exception:  # a malformed record is the logger's problem, not ours
            return True
        clean = scrub(message)
        if clean != message:
            record.msg, record.args = clean, None
        return True


_INSTALLED = False


def install_log_scrubbing() -> None:
    """Attach `ScrubFilter` to the SDK and HTTP loggers (idempotent)."""
    global _INSTALLED
    if _INSTALLED:
        return
    filt = ScrubFilter()
    for name in _SDK_LOGGERS:
        logging.getLogger(name).addFilter(filt)
    _INSTALLED = True
