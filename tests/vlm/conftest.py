"""Fixtures for VLM tests: loopback OpenAI/Gemini servers, fast configs, prompt factory.

`openai_server` and `gemini_server` wrap `rover.vlm.testing` (importable from any test
folder): real HTTP on 127.0.0.1 that records requests and answers from a script.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from rover.vlm import BackendConfig, ImagePart, Message, Prompt, PromptMeta, TextPart
from rover.vlm.testing import GeminiRESTServer, OpenAICompatServer

KEY_VARS = ("OPENAI_API_KEY", "OPENAI_BASE_URL", "GEMINI_API_KEY", "GOOGLE_API_KEY", "OPENAI_LOG")


@pytest.fixture(autouse=True)
def _hermetic_env(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """No real keys or endpoints leak in, and nothing is cached outside tmp_path."""
    for name in KEY_VARS:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("ROVER_CACHE_DIR", str(tmp_path / "default-cache"))


@pytest.fixture
def openai_server() -> Iterator[OpenAICompatServer]:
    """A live OpenAI-compatible server: `.base_url`, `.requests`, `.script(Reply...)`, `.answer`."""
    with OpenAICompatServer() as server:
        yield server


@pytest.fixture
def gemini_server() -> Iterator[GeminiRESTServer]:
    """A live Gemini-REST server (`POST /v1beta/models/<model>:generateContent`)."""
    with GeminiRESTServer() as server:
        yield server


@pytest.fixture
def fast_config(tmp_path: Path) -> BackendConfig:
    """Real retry behaviour with millisecond waits, and a cache inside tmp_path."""
    return BackendConfig(
        cache_path=tmp_path / "responses.sqlite",
        retry_base_wait_s=0.001,
        retry_max_wait_s=0.01,
        timeout_s=5.0,
        max_retries=3,
    )


def frame(seed: int, height: int = 48, width: int = 64) -> np.ndarray:
    """A distinct RGB frame per seed."""
    rng = np.random.default_rng(seed)
    return rng.integers(0, 255, size=(height, width, 3), dtype=np.uint8)


@pytest.fixture
def make_prompt() -> Callable[..., Prompt]:
    """Factory: a system + user prompt with `n_images` frames and a question."""

    def _make(
        question: str = "Describe the frame.",
        n_images: int = 1,
        kind: str = "test.ask",
        first_frame: int = 0,
        size: tuple[int, int] = (48, 64),
        detail: str | None = None,
    ) -> Prompt:
        indices = list(range(first_frame, first_frame + n_images))
        parts: list = [
            ImagePart.from_image(frame(i, *size), frame_index=i, detail=detail) for i in indices
        ]
        parts.append(TextPart(text=question))
        return Prompt(
            messages=[
                Message(role="system", content="You watch robot videos."),
                Message(role="user", content=parts),
            ],
            meta=PromptMeta(kind=kind, frame_indices=indices),
        )

    return _make
