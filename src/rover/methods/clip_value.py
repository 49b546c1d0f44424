"""clip-value: a LIV-style embedding baseline (paper Sec. 5: LIV, a CLIP fine-tuned for value).

Progress is how close each frame's image embedding is to the task text's embedding,
relative to the first frame and rescaled per video: frame 0 is 0, the frame most similar
to the task text is 100, frames less similar than the first frame are 0. It makes no VLM
calls. The model is any CLIP or SigLIP checkpoint loadable by `transformers` from a local
folder (`model_path`), e.g. LIV's released weights converted to CLIP format; nothing is
downloaded.
"""

from __future__ import annotations

import asyncio
import time
from pathlib import Path
from typing import Any

import numpy as np

from rover.episode import Episode
from rover.errors import InputError, MissingExtraError
from rover.methods.base import Method, OnStep
from rover.methods.trace import Totals, Trace


def _as_tensor(out: Any) -> Any:
    """Embedding tensors from either a tensor or a model output (transformers 4 vs 5)."""
    for attr in ("image_embeds", "text_embeds", "pooler_output"):
        val = getattr(out, attr, None)
        if val is not None:
            return val
    return out


class ClipValue(Method):
    """Per-frame similarity to the task text under a local CLIP/SigLIP model."""

    name = "clip-value"

    def __init__(
        self, model_path: str | Path | None = None, batch_size: int = 16, **_ignored: Any
    ) -> None:
        super().__init__(model_path=None if model_path is None else str(model_path))
        self.model_path = None if model_path is None else Path(model_path)
        self.batch_size = int(batch_size)

    def _load(self) -> tuple[Any, Any, Any]:
        if self.model_path is None:
            raise InputError(
                "clip-value needs model_path: a local folder with CLIP or SigLIP weights"
            )
        if not self.model_path.exists():
            raise InputError(f"clip-value: model folder {self.model_path} does not exist")
        try:
            import torch
            import transformers
        except ImportError as exc:
            raise MissingExtraError("torch", "hf", "the clip-value baseline") from exc
        try:
            model = transformers.AutoModel.from_pretrained(self.model_path, local_files_only=True)
            images = transformers.AutoImageProcessor.from_pretrained(
                self.model_path, local_files_only=True
            )
            tokenizer = transformers.AutoTokenizer.from_pretrained(
                self.model_path, local_files_only=True
            )
        except (OSError, ValueError) as exc:
            raise InputError(f"clip-value: cannot load {self.model_path}: {exc}") from exc
        model.eval()
        torch.set_grad_enabled(False)
        return model, images, tokenizer

    def similarities(self, frames: np.ndarray, task: str) -> np.ndarray:
        """Cosine similarity of every frame to the task text (blocking; runs in a thread)."""
        import torch

        model, images, tokenizer = self._load()
        with torch.no_grad():
            tok = tokenizer([task], padding=True, truncation=True, return_tensors="pt")
            txt = _as_tensor(model.get_text_features(**tok))
            txt = torch.nn.functional.normalize(txt.float(), dim=-1)
            sims = []
            for i in range(0, len(frames), self.batch_size):
                batch = images(images=list(frames[i : i + self.batch_size]), return_tensors="pt")
                emb = _as_tensor(model.get_image_features(pixel_values=batch["pixel_values"]))
                emb = torch.nn.functional.normalize(emb.float(), dim=-1)
                sims.append((emb @ txt.T)[:, 0].cpu().numpy())
        return np.concatenate(sims).astype(np.float64)

    @staticmethod
    def to_progress(sims: np.ndarray) -> list[float]:
        """Rescale per video: first frame 0, most task-like frame 100, clipped to 0..100."""
        rel = sims - sims[0]
        top = float(rel.max())
        if top <= 1e-12:
            return [0.0] * len(sims)
        return [float(v) for v in np.clip(100.0 * rel / top, 0.0, 100.0)]

    async def run(self, episode: Episode, vlm: Any = None, on_step: OnStep | None = None) -> Trace:
        t0 = time.perf_counter()
        frames = episode.frames()
        sims = await asyncio.to_thread(self.similarities, frames, episode.task)
        progress = self.to_progress(sims)
        model = self.model_path.name if self.model_path else ""
        trace = Trace.start(episode, self.name, self.params, "embedding", model)
        for fr in trace.frames:
            fr.progress = progress[fr.position]
            fr.predicted = True
            fr.subtask_progress = float(sims[fr.position])
        trace.totals = Totals(latency_s=time.perf_counter() - t0)
        if on_step is not None:
            from rover.methods.base import StepInfo

            on_step(StepInfo(position=episode.num_frames - 1, num_frames=episode.num_frames))
        from datetime import UTC, datetime

        trace.finished_at = datetime.now(UTC).isoformat()
        return trace
