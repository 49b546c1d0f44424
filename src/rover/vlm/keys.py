"""API keys: read only from environment variables, and scrubbed from anything we print.

Every key this process reads is remembered (in memory only) so that `scrub` (the one
scrubber, in `rover.vlm.scrub`) can remove it from error messages, log records and
anything written, whichever SDK produced them.
"""

from __future__ import annotations

import logging
import os
from urllib.parse import unquote, urlsplit

# one scrubber for the whole package: these names are re-exported for existing callers
from rover.vlm.scrub import REDACTED, register_secret, scrub, scrub_line, strip_controls

__all__ = [
    "REDACTED",
    "ScrubFilter",
    "install_log_scrubbing",
    "read_key",
    "register_secret",
    "register_url_secret",
    "scrub",
    "scrub_line",
    "strip_controls",
]

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


def read_key(*names: str) -> tuple[str | None, str | None]:
    """The first non-empty environment variable among `names`: (value, name) or (None, None)."""
    for name in names:
        value = os.environ.get(name)
        if value:
            register_secret(value)
            return value, name
    return None, None


def register_url_secret(url: str) -> None:
    """Remember the password (or token) in a URL's userinfo, so bare mentions are scrubbed."""
    try:
        parts = urlsplit(url)
        secrets = (parts.password, parts.username if parts.password is None else None)
    except ValueError:
        return
    for value in secrets:
        if value:
            register_secret(unquote(value))
            register_secret(value)


class ScrubFilter(logging.Filter):
    """Rewrites a log record's message scrubbed and without control characters (never drops it)."""

    def filter(self, record: logging.LogRecord) -> bool:
        try:
            message = record.getMessage()
        except Exception:  # a malformed record is the logger's problem, not ours
            return True
        clean = strip_controls(scrub(message))  # records reach terminals too
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
