"""The VLM interface every method talks through: prompts in, completions out.

Content parts are small pydantic models told apart by `type`, so a prompt is plain data:
hashable for the cache, serialisable for cassettes and traces, convertible by each
backend into its SDK's format and nothing else.
"""

from __future__ import annotations

import hashlib
import io
from collections import OrderedDict
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Protocol, runtime_checkable

import numpy as np
from PIL import Image
from pydantic import BaseModel, ConfigDict, Field

from rover.errors import InputError

if TYPE_CHECKING:
    from rover.episode import Episode


class ImageEncoding(BaseModel):
    """How images are turned into bytes before they are sent."""

    format: Literal["JPEG", "PNG"] = "JPEG"
    quality: int = 90
    max_side: int | None = None  # downscale so the long side is at most this (never upscale)


# LRU memo of encoded images: a long run keeps its recent frames hot instead of
# dropping everything when the memo fills up.
_ENCODED: OrderedDict[tuple[str, str], EncodedImage] = OrderedDict()
_ENCODED_MAX = 4096


class EncodedImage(BaseModel):
    """An image as the bytes a provider receives, with its content hash and size."""

    # base64 in JSON: encoded images are binary, and traces/cassettes must stay valid JSON
    model_config = ConfigDict(frozen=True, ser_json_bytes="base64", val_json_bytes="base64")

    data: bytes = Field(repr=False)
    mime: str
    width: int
    height: int
    sha256: str

    @classmethod
    def from_any(
        cls,
        image: Image.Image | np.ndarray | str | Path | bytes,
        enc: ImageEncoding | None = None,
        memo: bool = True,
    ) -> EncodedImage:
        """Encode once: identical pixels with identical settings come back from a memo.

        `memo=False` neither reads nor fills the memo (a live stream sees every frame once
        and keeps the few it still needs itself, so its memory stays flat)."""
        enc = enc or ImageEncoding()
        if isinstance(image, str | Path):
            if not Path(image).is_file():
                raise InputError(f"image file not found: {image}")
            image = Image.open(image)
        elif isinstance(image, bytes):
            image = Image.open(io.BytesIO(image))
        if isinstance(image, np.ndarray):
            arr = np.ascontiguousarray(image)
            if arr.dtype != np.uint8:
                raise ValueError(f"image arrays must be uint8, got {arr.dtype}")
        else:
            arr = None
            image = image.convert("RGB")
        memo_key = None
        if memo:  # the pixels' hash is the memo's key: not computed when it is not used
            if arr is not None:
                pixel_key = hashlib.sha256(arr.tobytes() + str(arr.shape).encode()).hexdigest()
            else:
                pixel_key = hashlib.sha256(image.tobytes() + str(image.size).encode()).hexdigest()
            memo_key = (pixel_key, enc.model_dump_json())
            hit = _ENCODED.get(memo_key)
            if hit is not None:
                _ENCODED.move_to_end(memo_key)
                return hit
        pil = Image.fromarray(arr) if arr is not None else image
        if pil.mode not in ("RGB", "L"):
            pil = pil.convert("RGB")  # JPEG has no alpha channel
        if enc.max_side and max(pil.size) > enc.max_side:
            s = enc.max_side / max(pil.size)
            pil = pil.resize((max(1, round(pil.width * s)), max(1, round(pil.height * s))))
        buf = io.BytesIO()
        if enc.format == "JPEG":
            pil.save(buf, format="JPEG", quality=enc.quality)
        else:
            pil.save(buf, format="PNG")
        data = buf.getvalue()
        out = cls(
            data=data,
            mime=f"image/{enc.format.lower()}",
            width=pil.width,
            height=pil.height,
            sha256=hashlib.sha256(data).hexdigest(),
        )
        if memo_key is None:
            return out
        _ENCODED[memo_key] = out
        while len(_ENCODED) > _ENCODED_MAX:
            _ENCODED.popitem(last=False)
        return out


class TextPart(BaseModel):
    type: Literal["text"] = "text"
    text: str


class ImagePart(BaseModel):
    type: Literal["image"] = "image"
    image: EncodedImage
    frame_index: int | None = None  # original frame index, for traces
    detail: Literal["auto", "low", "high"] | None = None  # OpenAI detail; None = backend default

    @classmethod
    def from_image(
        cls,
        image: Image.Image | np.ndarray | str | Path | bytes,
        *,
        frame_index: int | None = None,
        detail: Literal["auto", "low", "high"] | None = None,
        encoding: ImageEncoding | None = None,
    ) -> ImagePart:
        """Encode (once, memoised by pixel hash) and wrap an image for a prompt.

        Pass the backend's `vlm.image_encoding` as `encoding` so the bytes sent follow the
        user's `--image-format/--image-quality/--image-max-side` choices.
        """
        return cls(
            image=EncodedImage.from_any(image, encoding),
            frame_index=frame_index,
            detail=detail,
        )


Part = Annotated[TextPart | ImagePart, Field(discriminator="type")]


class Message(BaseModel):
    role: Literal["system", "user", "assistant"]
    content: str | list[Part]

    def parts(self) -> list[TextPart | ImagePart]:
        return [TextPart(text=self.content)] if isinstance(self.content, str) else self.content


class PromptMeta(BaseModel):
    """What the caller is asking; real backends ignore it, traces and the oracle read it.

    `kind` names the question (see `rover.methods` for the vocabulary, e.g. "rover.step",
    "gvl.batch", "concat.frame", "judge.frame", "qa.answer"); `frame_indices` are the
    original indices of the frames shown, in the order shown; `subtask` is the line of
    reasoning's current (sub)task text and `subtask_path` the chain from the root task.
    """

    kind: str
    frame_indices: list[int] = Field(default_factory=list)
    positions: list[int] = Field(default_factory=list)  # sampled positions of those frames
    subtask: str | None = None
    subtask_path: list[str] = Field(default_factory=list)
    extra: dict[str, Any] = Field(default_factory=dict)


class Prompt(BaseModel):
    messages: list[Message]
    meta: PromptMeta

    def images(self) -> list[ImagePart]:
        return [p for m in self.messages for p in m.parts() if isinstance(p, ImagePart)]

    def describe(self) -> str:
        """A short label for error messages: what was asked and which frames were shown."""
        return f"kind={self.meta.kind} frames={self.meta.frame_indices}"

    def fingerprint(self) -> str:
        """Hash of what a provider sees (roles, text, image hashes), never of meta."""
        h = hashlib.sha256()
        for m in self.messages:
            h.update(b"\x00role:" + m.role.encode())
            for p in m.parts():
                if isinstance(p, TextPart):
                    h.update(b"\x00text:" + p.text.encode())
                else:
                    h.update(f"\x00image:{p.image.sha256}:{p.detail}".encode())
        return h.hexdigest()


class SamplingParams(BaseModel):
    temperature: float = 0.0
    max_tokens: int = 512
    seed: int | None = 0


class Usage(BaseModel):
    prompt_tokens: int = 0
    completion_tokens: int = 0
    image_tokens: int = 0  # part of prompt_tokens, when known
    source: Literal["reported", "estimated"] = "estimated"
    # part of prompt_tokens the provider served from its prompt-prefix cache (OpenAI and
    # vLLM `prompt_tokens_details.cached_tokens`, Gemini `cached_content_token_count`);
    # 0 when it reported none (old traces and caches read as 0 too)
    cached_prompt_tokens: int = 0

    @property
    def total_tokens(self) -> int:
        return self.prompt_tokens + self.completion_tokens

    @property
    def uncached_prompt_tokens(self) -> int:
        """Prompt tokens the provider processed afresh (billed at the full input price)."""
        return max(self.prompt_tokens - self.cached_prompt_tokens, 0)


class Completion(BaseModel):
    text: str
    usage: Usage = Field(default_factory=Usage)
    latency_s: float = 0.0
    cached: bool = False
    backend: str = ""
    model: str = ""
    # why generation stopped, as the provider said ("stop", "length", Gemini "MAX_TOKENS")
    finish_reason: str | None = None
    truncated: bool = False  # the reply stopped at the completion budget (max_tokens)


@runtime_checkable
class VLM(Protocol):
    """What methods need from a backend: one async call, plus per-episode binding."""

    backend: str  # "openai", "gemini", "hf", "oracle", "replay"
    model: str

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        """Answer one prompt (retries, cache, concurrency limits already applied)."""
        ...

    def bind(self, episode: Episode) -> VLM:
        """The VLM to use for this episode (the oracle reads its ground truth; others: self)."""
        ...
