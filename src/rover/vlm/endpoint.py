"""Endpoint URLs: checked before use, and named without their credentials.

`openai:m@127.0.0.1:8000/v1` (no scheme) once fell through to the public API with the real
key; a URL must now say `http://` or `https://` and name a host. `endpoint_identity` is
the URL as the cache key and every message see it: credentials removed, scheme and host
lower-cased, no trailing slash.
"""

from __future__ import annotations

from urllib.parse import urlsplit, urlunsplit

from rover.errors import InputError
from rover.vlm.scrub import scrub_line


def check_base_url(url: str, label: str) -> str:
    """`url` stripped, if it is an http(s) URL with a host; else InputError naming it."""
    url = url.strip()
    shown = scrub_line(url, 120)
    try:
        parts = urlsplit(url)
        port = parts.port  # raises ValueError on a malformed port
    except ValueError as exc:
        raise InputError(f"{label}: malformed base URL {shown!r} ({exc})") from None
    if parts.scheme.lower() not in ("http", "https"):
        raise InputError(
            f"{label}: base URL {shown!r} needs an explicit scheme: http://... or https://..."
        )
    if not parts.hostname:
        raise InputError(f"{label}: base URL {shown!r} names no host")
    if any(c.isspace() for c in url):
        raise InputError(f"{label}: base URL {shown!r} contains whitespace")
    del port
    return url


def endpoint_identity(url: str) -> str:
    """The server a URL points at, without user, password, query or fragment."""
    try:
        parts = urlsplit(url.strip())
        host = (parts.hostname or "").lower()
        port = parts.port
    except ValueError:
        return scrub_line(url, None)
    netloc = host if port is None else f"{host}:{port}"
    path = parts.path.rstrip("/")
    return urlunsplit((parts.scheme.lower(), netloc, path, "", ""))
