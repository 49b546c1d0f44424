"""BackendConfig: every knob a VLM backend reads, in one pydantic model.

Commands build it from their options (see `rover.vlm.cli_options`); library users build it
directly. It never holds an API key, only the *name* of the environment variable to read
one from, so a config can be logged or written to a run directory safely.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from rover.vlm.types import ImageEncoding, SamplingParams

TokenRule = Literal["openai-high", "openai-low", "gemini"]
Detail = Literal["auto", "low", "high"]

DEFAULT_CACHE_FILE = "responses.sqlite"


def default_cache_path() -> Path:
    """`$ROVER_CACHE_DIR/responses.sqlite`, else `~/.cache/rover/responses.sqlite`."""
    root = os.environ.get("ROVER_CACHE_DIR")
    base = Path(root).expanduser() if root else Path.home() / ".cache" / "rover"
    return base / DEFAULT_CACHE_FILE


BACKEND_ENV = "ROVER_BACKEND"
CONFIG_ENV = "ROVER_CONFIG"


def config_file_path() -> Path:
    """`$ROVER_CONFIG`, else `~/.config/rover/config.toml` (it need not exist)."""
    given = os.environ.get(CONFIG_ENV)
    return Path(given).expanduser() if given else Path.home() / ".config" / "rover" / "config.toml"


def default_backend() -> str | None:
    """The VLM spec the user chose once for all commands, or None when they chose none.

    `ROVER_BACKEND` wins over the config file's top-level `backend = "..."`. There is no
    built-in default: a silent one would either spend money or (the oracle) refuse real
    videos, so commands ask for an explicit choice instead.
    """
    env = os.environ.get(BACKEND_ENV, "").strip()
    if env:
        return env
    path = config_file_path()
    if not path.is_file():
        return None
    import tomllib

    from rover.errors import InputError

    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: invalid TOML ({exc})") from None
    value = data.get("backend")
    if value is not None and not isinstance(value, str):
        raise InputError(f"{path}: 'backend' must be a VLM spec string")
    spec = value.strip() or None if value else None
    return _with_pool(spec, data.get("base_urls"), path)


def _with_pool(spec: str | None, urls: object, path: Path) -> str | None:
    """`backend` plus the file's `base_urls = [...]` list (replicas of that model) as one
    spec, `openai:<model>@<url>,<url>`."""
    from rover.errors import InputError

    if urls is None:
        return spec
    if not isinstance(urls, list) or not urls or not all(isinstance(u, str) for u in urls):
        raise InputError(f"{path}: 'base_urls' must be a non-empty list of URL strings")
    if spec is None or not spec.lower().startswith("openai:"):
        raise InputError(f"{path}: 'base_urls' needs 'backend = \"openai:<model>\"' beside it")
    if "@" in spec:
        raise InputError(f"{path}: give the server once: in 'backend' after '@' or in 'base_urls'")
    return spec + "@" + ",".join(u.strip() for u in urls)


class BackendConfig(BaseModel):
    """How to reach a VLM and how to treat its answers.

    Defaults suit a real API: 8 calls in flight, 60 s per call (10 s to connect), 6 retries
    with backoff capped at 60 s (1 after a timeout, 2 on a dead endpoint or malformed body),
    answers cached on disk. Tests shrink the waits to milliseconds.
    """

    model_config = ConfigDict(extra="forbid")

    # response cache (SQLite); None = default_cache_path()
    cache_path: Path | None = None
    no_cache: bool = False
    # write every completion to this cassette (JSONL) for `replay:<file>`
    record: Path | None = None

    # calls in flight per backend (an asyncio.Semaphore per event loop)
    concurrency: int = Field(default=8, ge=1)
    # per-call timeout in seconds (one attempt; retries get a fresh timeout each)
    timeout_s: float = Field(default=60.0, gt=0)
    # seconds to establish a connection: a dead endpoint fails in seconds, not minutes
    connect_timeout_s: float = Field(default=10.0, gt=0)
    # retries after a timeout (each one costs a whole timeout_s)
    timeout_retries: int = Field(default=1, ge=0)
    # retries after the first attempt on rate limits, 5xx, timeouts and connection errors
    max_retries: int = Field(default=6, ge=0)
    # backoff: base * 2**attempt with jitter, and Retry-After, both capped at retry_max_wait_s
    retry_base_wait_s: float = Field(default=1.0, ge=0)
    retry_max_wait_s: float = Field(default=60.0, ge=0)

    # environment variable holding the API key (None = the provider's usual names)
    api_key_env: str | None = None
    # endpoint override (openai: same as `openai:<model>@<url>`; gemini: REST base URL);
    # openai: several URLs (a list, or comma-separated) are replicas of one model, a pool
    base_url: str | list[str] | None = None
    # seconds a pool replica that failed (connect error, 5xx, timeout) is passed over
    pool_cooldown_s: float = Field(default=30.0, ge=0)

    # how images are encoded before they are sent
    image_format: Literal["JPEG", "PNG"] = "JPEG"
    image_quality: int = Field(default=90, ge=1, le=100)
    image_max_side: int | None = Field(default=None, ge=16)
    # OpenAI image detail for parts that do not set their own
    detail: Detail = "auto"
    # image-token rule for estimated usage (None = the backend's own, see rover.vlm.tokens)
    token_rule: TokenRule | None = None

    # sampling
    temperature: float = Field(default=0.0, ge=0)
    max_tokens: int = Field(default=512, ge=1)
    sampling_seed: int | None = 0

    # hf backend: "cpu", "cuda", "cuda:1"...; None = cuda when available, else cpu
    device: str | None = None

    # oracle noise knobs (read by rover.vlm.oracle)
    seed: int = 0
    flip_prob: float = Field(default=0.0, ge=0, le=1)
    jitter: float = Field(default=0.0, ge=0)

    def resolved_cache_path(self) -> Path:
        return Path(self.cache_path).expanduser() if self.cache_path else default_cache_path()

    def image_encoding(self) -> ImageEncoding:
        return ImageEncoding(
            format=self.image_format, quality=self.image_quality, max_side=self.image_max_side
        )

    def sampling(self) -> SamplingParams:
        return SamplingParams(
            temperature=self.temperature, max_tokens=self.max_tokens, seed=self.sampling_seed
        )
