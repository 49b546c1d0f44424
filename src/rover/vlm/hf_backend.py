"""`hf:<local path>`: Qwen2-VL / Qwen2.5-VL / Qwen3-VL weights on this machine, via transformers.

Loads offline only (`local_files_only=True`): rover never downloads weights. The prompt is
rendered with the checkpoint's own chat template. When the checkpoint's full processor
cannot be built (transformers' Qwen video processor needs torchvision, which an image-only
install may lack), the tokenizer and image processor are used directly: the image
placeholder is expanded to the number of visual tokens the image processor reports,
exactly what the processor would do for images.

Usage is counted exactly from the model's own tokenizer (prompt, image and generated
tokens) and labelled "reported"; set `token_rule` to get published-rule estimates instead.
"""

from __future__ import annotations

import asyncio
import inspect
import io
import threading
from pathlib import Path
from typing import Any

from rover.errors import BackendError, InputError, MissingExtraError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig, TokenRule
from rover.vlm.retry import ErrorInfo, ErrorKind
from rover.vlm.types import Prompt, SamplingParams, TextPart, Usage


def _require_hf() -> None:
    try:
        import torch  # noqa: F401
        import transformers  # noqa: F401
    except ImportError as exc:
        raise MissingExtraError(exc.name or "transformers", "hf", "the hf backend") from exc


class HFBackend(BaseBackend):
    backend = "hf"

    def __init__(self, path: str, config: BackendConfig | None = None) -> None:
        super().__init__(path, config)
        _require_hf()
        self.path = Path(path).expanduser()
        if not (self.path / "config.json").is_file():
            raise InputError(
                f"hf:{path}: no model folder with a config.json there "
                "(the hf backend loads local weights only; download them first)"
            )
        self._load_lock = threading.Lock()
        self._run_lock = threading.Lock()  # one generate at a time per model
        self._state: dict[str, Any] | None = None

    @property
    def token_rule(self) -> TokenRule:
        return self.config.token_rule or "gemini"

    def _retry_policy(self) -> Any:
        # local compute: nothing transient to wait out, and a thread cannot be cancelled
        policy = super()._retry_policy()
        return type(policy)(max_retries=0, timeout_s=None)

    def _classify(self, exc: BaseException) -> ErrorInfo | None:
        if type(exc).__name__ == "OutOfMemoryError":
            return ErrorInfo(ErrorKind.fatal, "out of GPU memory; try --device cpu or fewer frames")
        return None

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        return await asyncio.to_thread(self._generate_sync, prompt, params)

    # --- loading -----------------------------------------------------------------------

    def _load(self) -> dict[str, Any]:
        with self._load_lock:
            if self._state is None:
                self._state = self._load_now()
            return self._state

    def _load_now(self) -> dict[str, Any]:
        import torch
        from transformers import AutoModelForImageTextToText

        device = self.config.device or ("cuda" if torch.cuda.is_available() else "cpu")
        dtype = torch.bfloat16 if device.startswith("cuda") else torch.float32
        try:
            model = AutoModelForImageTextToText.from_pretrained(
                self.path, local_files_only=True, dtype=dtype
            )
        except (OSError, ValueError) as exc:
            raise InputError(f"hf:{self.path}: cannot load the model: {exc}") from exc
        model = model.to(device).eval()
        state: dict[str, Any] = {"model": model, "device": device}
        state.update(self._load_processing(model))
        return state

    def _load_processing(self, model: Any) -> dict[str, Any]:
        from transformers import AutoImageProcessor, AutoProcessor, AutoTokenizer

        try:
            processor = AutoProcessor.from_pretrained(self.path, local_files_only=True)
            if getattr(processor, "chat_template", None) and hasattr(processor, "tokenizer"):
                return {"processor": processor, "tokenizer": processor.tokenizer}
        except Exception:  # e.g. the video processor needs torchvision: use the parts
            pass
        try:
            tokenizer = AutoTokenizer.from_pretrained(self.path, local_files_only=True)
            image_processor = AutoImageProcessor.from_pretrained(self.path, local_files_only=True)
        except (OSError, ValueError) as exc:
            raise InputError(f"hf:{self.path}: cannot load tokenizer/processor: {exc}") from exc
        if not getattr(tokenizer, "chat_template", None):
            raise InputError(f"hf:{self.path}: the checkpoint has no chat template")
        image_token_id = getattr(model.config, "image_token_id", None)
        if image_token_id is None:
            raise InputError(f"hf:{self.path}: not a vision-language model (no image_token_id)")
        return {
            "processor": None,
            "tokenizer": tokenizer,
            "image_processor": image_processor,
            "image_token_id": image_token_id,
            "image_token": tokenizer.convert_ids_to_tokens(image_token_id),
        }

    # --- one call ----------------------------------------------------------------------

    def _inputs(self, state: dict[str, Any], prompt: Prompt) -> dict[str, Any]:
        from PIL import Image

        messages: list[dict[str, Any]] = []
        images: list[Any] = []
        for message in prompt.messages:
            content: list[dict[str, Any]] = []
            for part in message.parts():
                if isinstance(part, TextPart):
                    content.append({"type": "text", "text": part.text})
                else:
                    content.append({"type": "image"})
                    images.append(Image.open(io.BytesIO(part.image.data)).convert("RGB"))
            messages.append({"role": message.role, "content": content})
        processor = state["processor"]
        if processor is not None:
            text = processor.apply_chat_template(
                messages, add_generation_prompt=True, tokenize=False
            )
            return dict(processor(text=[text], images=images or None, return_tensors="pt"))
        tokenizer = state["tokenizer"]
        text = tokenizer.apply_chat_template(messages, add_generation_prompt=True, tokenize=False)
        inputs: dict[str, Any] = {}
        if images:
            vision = state["image_processor"](images=images, return_tensors="pt")
            merge = getattr(state["image_processor"], "merge_size", 2) ** 2
            pieces = text.split(state["image_token"])
            if len(pieces) != len(images) + 1:
                raise BackendError(
                    f"hf:{self.path}: chat template placed {len(pieces) - 1} image slots "
                    f"for {len(images)} images"
                )
            counts = [int(g.prod()) // merge for g in vision["image_grid_thw"]]
            text = pieces[0] + "".join(
                state["image_token"] * n + rest for n, rest in zip(counts, pieces[1:], strict=True)
            )
            inputs.update(vision)
        encoded = tokenizer(text, add_special_tokens=False, return_tensors="pt")
        inputs.update(encoded)
        forward = inspect.signature(state["model"].forward).parameters
        if "mm_token_type_ids" in forward:
            inputs["mm_token_type_ids"] = (encoded["input_ids"] == state["image_token_id"]).long()
        return inputs

    def _generate_sync(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        import torch

        state = self._load()
        model, tokenizer = state["model"], state["tokenizer"]
        inputs = {
            k: (v.to(state["device"]) if hasattr(v, "to") else v)
            for k, v in self._inputs(state, prompt).items()
        }
        sampling: dict[str, Any] = {"do_sample": params.temperature > 0}
        if params.temperature > 0:
            sampling["temperature"] = params.temperature
        with self._run_lock, torch.inference_mode():
            if params.temperature > 0 and params.seed is not None:
                torch.manual_seed(params.seed)
            out = model.generate(**inputs, max_new_tokens=params.max_tokens, **sampling)
        prompt_ids = inputs["input_ids"][0]
        generated = out[0, prompt_ids.shape[0] :]
        text = tokenizer.decode(generated, skip_special_tokens=True).strip()
        usage = None
        if self.config.token_rule is None:
            image_id = getattr(model.config, "image_token_id", None)
            usage = Usage(
                prompt_tokens=int(prompt_ids.shape[0]),
                completion_tokens=_generated_length(generated, tokenizer),
                image_tokens=int((prompt_ids == image_id).sum()) if image_id is not None else 0,
                source="reported",
            )
        # stopped for length: no end-of-sequence token within the max_new_tokens generated
        ids = generated.tolist()
        truncated = _generated_length(generated, tokenizer) == len(ids) >= params.max_tokens
        return RawAnswer(
            text=text,
            usage=usage,
            finish_reason="length" if truncated else "stop",
            truncated=truncated,
        )


def _generated_length(generated: Any, tokenizer: Any) -> int:
    """Generated tokens up to and including the first end-of-sequence (padding excluded)."""
    ids = generated.tolist()
    stops = {tokenizer.eos_token_id, tokenizer.pad_token_id} - {None}
    for i, token in enumerate(ids):
        if token in stops:
            return i + 1
    return len(ids)
