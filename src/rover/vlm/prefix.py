"""How much of each prompt repeats an earlier prompt's beginning: what a prefix cache can reuse.

Providers cache the *beginning* of a prompt (OpenAI and Gemini implicitly, vLLM and SGLang
with automatic prefix caching), so the tokens a call can be billed at the cached price
are those of the longest prefix it shares with a prompt sent before it. `PrefixTracker`
measures exactly that from the request as it is sent: messages in order (system text
joined as the OpenAI conversion joins it), each message's role overhead, text parts as
GPT-4o tokens, images as a whole (same bytes and detail, or not) at the token rule's
count. A text part that matches only partly counts its common leading tokens.

It is an upper bound on what a real cache reuses: providers cache in blocks (vLLM: 16
tokens; OpenAI: from 1,024 tokens, in steps of 128) and evict under load.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from rover.vlm.tokens import TOKENS_PER_MESSAGE, _encoding, _image_rule, estimate_image_tokens
from rover.vlm.types import ImagePart, Prompt, TextPart

Segment = tuple[tuple[Any, ...], int]  # (key, tokens): equal keys are the same tokens


def _text_ids(text: str) -> tuple[int, ...]:
    enc = _encoding()
    if enc is None:  # no tokenizer: 4 characters per token, compared chunk by chunk
        return tuple(hash(text[i : i + 4]) for i in range(0, len(text), 4))
    return tuple(enc.encode(text, disallowed_special=()))


def prompt_segments(prompt: Prompt, rule: str = "gemini") -> list[Segment]:
    """The prompt as the provider reads it, in order: role marks, text runs, images."""
    out: list[Segment] = []
    for message in prompt.messages:
        out.append((("role", message.role), TOKENS_PER_MESSAGE))
        parts = message.parts()
        if message.role != "user" or all(isinstance(p, TextPart) for p in parts):
            text = "\n".join(p.text for p in parts if isinstance(p, TextPart))
            ids = _text_ids(text)
            out.append((("text", ids), len(ids)))
            continue
        for p in parts:
            if isinstance(p, TextPart):
                ids = _text_ids(p.text)
                out.append((("text", ids), len(ids)))
            elif isinstance(p, ImagePart):
                n = estimate_image_tokens(p.image.width, p.image.height, _image_rule(p, rule))  # type: ignore[arg-type]
                out.append((("image", p.image.sha256, p.detail), n))
    return out


def _common(a: tuple[int, ...], b: tuple[int, ...]) -> int:
    n = 0
    for x, y in zip(a, b, strict=False):
        if x != y:
            break
        n += 1
    return n


@dataclass
class _Node:
    children: dict[tuple[Any, ...], _Node] = field(default_factory=dict)


class PrefixTracker:
    """Prompts of one video in the order they were sent; `add` says how much of each one
    repeats the longest matching beginning of an earlier one (a trie of segments)."""

    def __init__(self, rule: str = "gemini") -> None:
        self.rule = rule
        self._root = _Node()
        self.calls = 0
        self.prompt_tokens = 0
        self.repeated_tokens = 0

    def add(self, prompt: Prompt) -> tuple[int, int]:
        """(repeated prefix tokens, prompt tokens) of `prompt`; then remember it."""
        node, repeated, matching, total = self._root, 0, True, 0
        for key, n in prompt_segments(prompt, self.rule):
            total += n
            if matching:
                child = node.children.get(key)
                if child is not None:
                    repeated += n
                    node = child
                    continue
                matching = False
                if key[0] == "text":  # the part where two prompts first differ
                    repeated += max(
                        (_common(key[1], k[1]) for k in node.children if k[0] == "text"),
                        default=0,
                    )
            node = node.children.setdefault(key, _Node())
        self.calls += 1
        self.prompt_tokens += total
        self.repeated_tokens += repeated
        return repeated, total

    @property
    def share(self) -> float:
        """Repeated-prefix tokens as a fraction of all prompt tokens so far (0 if none)."""
        return self.repeated_tokens / self.prompt_tokens if self.prompt_tokens else 0.0


VLLM_BLOCK = 16  # vLLM's default KV-cache block size: only whole blocks are reused
OPENAI_MIN_CACHED = 1024  # OpenAI caches prompts from 1,024 tokens ...
OPENAI_CACHE_STEP = 128  # ... in steps of 128


def vllm_cached(repeated: int, block: int = VLLM_BLOCK) -> int:
    """What vLLM's automatic prefix caching can reuse of `repeated` tokens: whole blocks."""
    return (repeated // block) * block


def openai_cached(repeated: int) -> int:
    """What OpenAI's prompt caching can report of `repeated` tokens (0 below 1,024)."""
    if repeated < OPENAI_MIN_CACHED:
        return 0
    return (
        OPENAI_MIN_CACHED
        + ((repeated - OPENAI_MIN_CACHED) // OPENAI_CACHE_STEP) * OPENAI_CACHE_STEP
    )
