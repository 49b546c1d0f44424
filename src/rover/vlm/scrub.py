"""The one scrubber: every secret shape rover knows, removed before text is written or shown.

Run directories, traces, cassettes, the response cache and error messages are meant to be
shared, so whatever reaches them passes through `scrub` first: API keys this process read
(remembered in memory by `register_secret`), credentials in URLs (`http://user:pw@host`),
`Authorization` / API-key header values echoed back by a server or proxy, and key-shaped
tokens we never read ourselves (`sk-…`, `AIza…`, `hf_…`, bearer/basic tokens, `?key=`
query values). `scrub_line` also folds the text onto one line, strips control characters
and only then truncates, so a cut can never leave the prefix of a secret behind.

Every pattern is a single pass without nested quantifiers: linear in the text's length.
"""

from __future__ import annotations

import re
import threading

REDACTED = "<redacted>"

_KNOWN: set[str] = set()
_LOCK = threading.Lock()

# credentials in a URL: scheme://user:password@host or scheme://token@host
_URL_USERINFO = re.compile(r"(\b[A-Za-z][A-Za-z0-9+.\-]{0,15}://)[^/?#@\s\"'<>]+@")
# provider key shapes (OpenAI/Anthropic sk-, Google AIza, Hugging Face hf_, GitHub tokens)
_KEY_SHAPES = re.compile(
    r"\bsk-[A-Za-z0-9_\-]{8,}|\bAIza[0-9A-Za-z_\-]{20,}|\bhf_[A-Za-z0-9]{16,}"
    r"|\bgh[pousr]_[A-Za-z0-9]{20,}"
)
# header-style assignments whose value is a credential, as echoed in error bodies or logs
_HEADER_VALUE = re.compile(
    r"(?i)(\b(?:proxy-)?authorization|\bx-goog-api-key|\bx-api-key|\bapi-key)"
    r"([\"']?\s*[:=]\s*[\"']?)(?:(basic|bearer|token|digest)\s+)?([^\s\"',;}]+)"
)
# a scheme word followed by a token, outside any header ("... Bearer abc123 ...")
_SCHEME_TOKEN = re.compile(r"(?i)\b(bearer|basic)\s+([A-Za-z0-9+/=._\-]{8,})")
# secret values in query strings (Gemini's REST API takes ?key=...)
_QUERY_SECRET = re.compile(
    r"(?i)([?&](?:api[_-]?key|key|token|access_token|secret|password)=)[^&\s\"'#]+"
)
# terminal escape sequences (CSI, OSC) and the remaining C0/C1 controls and bidi overrides
_ESCAPE_SEQ = re.compile(r"\x1b\[[0-?]*[ -/]*[@-~]|\x1b\][^\x07\x1b]*(?:\x07|\x1b\\)?|\x1b.?")
_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]")


def register_secret(value: str) -> None:
    """Remember a secret so `scrub` removes it; short values are ignored (too many false hits)."""
    if value and len(value) >= 6:
        with _LOCK:
            _KNOWN.add(value)


def _looks_like_token(token: str) -> bool:
    """A credential rather than a word: digits, base64 padding/symbols, or mixed case."""
    if any(c.isdigit() or c in "+/=_" for c in token):
        return True
    upper = sum(c.isupper() for c in token)
    return upper >= 2 and upper < len(token)


def _header_sub(match: re.Match[str]) -> str:
    scheme = f"{match.group(3)} " if match.group(3) else ""
    return f"{match.group(1)}{match.group(2)}{scheme}{REDACTED}"


def _scheme_sub(match: re.Match[str]) -> str:
    if not _looks_like_token(match.group(2)):
        return match.group(0)
    return f"{match.group(1)} {REDACTED}"


def scrub(text: str) -> str:
    """`text` with every known secret and credential-shaped string replaced by <redacted>."""
    if not text:
        return text
    with _LOCK:
        known = sorted(_KNOWN, key=len, reverse=True)
    for secret in known:
        if secret in text:
            text = text.replace(secret, REDACTED)
    text = _URL_USERINFO.sub(r"\1" + REDACTED + "@", text)
    text = _HEADER_VALUE.sub(_header_sub, text)
    text = _SCHEME_TOKEN.sub(_scheme_sub, text)
    text = _KEY_SHAPES.sub(REDACTED, text)
    return _QUERY_SECRET.sub(r"\1" + REDACTED, text)


def strip_controls(text: str) -> str:
    """`text` without terminal escape sequences or control characters (newline and tab kept)."""
    return _CONTROL.sub("", _ESCAPE_SEQ.sub("", text))


def scrub_line(text: str, limit: int | None = 300) -> str:
    """One safe line: scrubbed, controls stripped, whitespace folded, *then* cut to `limit`."""
    line = " ".join(strip_controls(scrub(str(text))).split())
    if limit is not None and len(line) > limit:
        line = line[: max(0, limit - 1)] + "…"
    return line
