"""The VLM layer: one small interface in front of every vision-language model.

Methods build a `Prompt` (messages of text and image parts, plus `meta` saying what is
asked) and `await vlm.complete(prompt)` for a `Completion` (text, usage, latency,
cached). `load_vlm(spec, config)` picks the backend from a spec string:
`openai:<model>[@<base_url>]`, `gemini:<model>`, `hf:<path>`, `oracle`, `replay:<file>`.

Importing this package loads no provider SDK; each is imported when its spec is used.
"""

from __future__ import annotations

from rover.vlm.config import BackendConfig, default_cache_path
from rover.vlm.loader import load_vlm, parse_spec
from rover.vlm.tokens import (
    default_rule,
    estimate_image_tokens,
    estimate_prompt_tokens,
    estimate_text_tokens,
    estimate_usage,
)
from rover.vlm.types import (
    VLM,
    Completion,
    EncodedImage,
    ImageEncoding,
    ImagePart,
    Message,
    Part,
    Prompt,
    PromptMeta,
    SamplingParams,
    TextPart,
    Usage,
)

__all__ = [
    "VLM",
    "BackendConfig",
    "Completion",
    "EncodedImage",
    "ImageEncoding",
    "ImagePart",
    "Message",
    "Part",
    "Prompt",
    "PromptMeta",
    "SamplingParams",
    "TextPart",
    "Usage",
    "default_cache_path",
    "default_rule",
    "estimate_image_tokens",
    "estimate_prompt_tokens",
    "estimate_text_tokens",
    "estimate_usage",
    "load_vlm",
    "parse_spec",
]
