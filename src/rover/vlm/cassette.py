"""Cassettes: recorded completions (JSONL) that make a run reproducible without a model.

`--record FILE` on any backend appends one line per completion; `replay:FILE` answers the
same prompts from it. A line holds the prompt's key (fingerprint + sampling parameters),
the prompt kind and frames (for humans and error messages), the answer and its usage —
never images and never a key. Lines are appended and flushed one at a time, so an
interrupted recording keeps everything finished before the interruption.
"""

from __future__ import annotations

import hashlib
import json
import threading
from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from rover.errors import BackendError, InputError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.scrub import scrub
from rover.vlm.tokens import estimate_usage
from rover.vlm.types import Completion, Prompt, SamplingParams, Usage

if TYPE_CHECKING:
    from rover.episode import Episode
    from rover.vlm.types import VLM

CASSETTE_VERSION = 1


def cassette_key(prompt: Prompt, params: SamplingParams) -> str:
    """Like the cache key, minus backend and model: a cassette replays under any name."""
    payload = json.dumps(
        {"v": CASSETTE_VERSION, "prompt": prompt.fingerprint(), "params": params.model_dump()},
        sort_keys=True,
    )
    return hashlib.sha256(payload.encode()).hexdigest()


class CassetteWriter:
    """Appends completions to a JSONL file; one writer may be shared by many tasks/threads."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path).expanduser()
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create {self.path.parent} for the cassette: {exc}") from exc
        self._lock = threading.Lock()

    def write(self, prompt: Prompt, params: SamplingParams, completion: Completion) -> None:
        entry = {
            "v": CASSETTE_VERSION,
            "key": cassette_key(prompt, params),
            "prompt": prompt.fingerprint(),
            "kind": prompt.meta.kind,
            "frames": prompt.meta.frame_indices,
            "backend": completion.backend,
            "model": completion.model,
            "text": scrub(completion.text),  # cassettes are shared: no echoed key in them
            "usage": completion.usage.model_dump(),
            "latency_s": completion.latency_s,
            "finish_reason": completion.finish_reason,
            "truncated": completion.truncated,
        }
        line = json.dumps(entry, ensure_ascii=False) + "\n"
        with self._lock, self.path.open("a", encoding="utf-8") as f:
            f.write(line)
            f.flush()


class RecordingVLM:
    """Wraps any VLM and writes each completion it returns to a cassette."""

    def __init__(self, inner: VLM, writer: CassetteWriter) -> None:
        self.inner = inner
        self.writer = writer

    @property
    def backend(self) -> str:
        return self.inner.backend

    @property
    def model(self) -> str:
        return self.inner.model

    def __getattr__(self, name: str) -> Any:  # config, image_encoding, token_rule, ...
        return getattr(self.inner, name)

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        params = params or _default_params(self.inner)
        completion = await self.inner.complete(prompt, params)
        self.writer.write(prompt, params, completion)
        return completion

    def bind(self, episode: Episode) -> RecordingVLM:
        return RecordingVLM(self.inner.bind(episode), self.writer)

    def __repr__(self) -> str:
        return f"<RecordingVLM {self.inner!r} -> {self.writer.path}>"


def _default_params(vlm: Any) -> SamplingParams:
    make = getattr(vlm, "default_params", None)
    if make is not None:
        return make()
    config = getattr(vlm, "config", None)
    return config.sampling() if isinstance(config, BackendConfig) else SamplingParams()


class ReplayBackend(BaseBackend):
    """`replay:<file>`: answers from a cassette, in recorded order for repeated prompts."""

    backend = "replay"
    use_cache: ClassVar[bool] = False

    def __init__(self, path: str | Path, config: BackendConfig | None = None) -> None:
        super().__init__(str(path), config)
        self.path = Path(path).expanduser()
        self._by_key: dict[str, list[dict[str, Any]]] = defaultdict(list)
        self._by_prompt: dict[str, list[dict[str, Any]]] = defaultdict(list)
        self._served: dict[str, int] = defaultdict(int)
        self._lock = threading.Lock()
        self._read()
        if not self._by_key:
            raise InputError(f"replay: {self.path} holds no recorded completions")
        models = {str(e.get("model")) for entries in self._by_key.values() for e in entries}
        self.recorded_models = sorted(models)

    def _read(self) -> None:
        if not self.path.is_file():
            raise InputError(f"replay: no cassette at {self.path}")
        try:
            lines = self.path.read_text(encoding="utf-8").splitlines()
        except UnicodeDecodeError as exc:
            raise InputError(
                f"replay: {self.path} is not a UTF-8 text cassette (byte {exc.start})"
            ) from None
        except OSError as exc:
            raise InputError(f"replay: cannot read {self.path}: {exc.strerror or exc}") from None
        for number, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                entry = json.loads(line)
                key, prompt, text = entry["key"], entry["prompt"], entry["text"]
                if not all(isinstance(x, str) for x in (key, prompt, text)):
                    raise TypeError("key, prompt and text must be strings")
                if entry.get("usage") is not None:
                    Usage.model_validate(entry["usage"])
            except (ValueError, KeyError, TypeError) as exc:  # pydantic errors are ValueErrors
                if number == len(lines):  # a recording cut off mid-line: drop only that line
                    break
                raise InputError(f"replay: {self.path} line {number} is malformed") from exc
            self._by_key[key].append(entry)
            self._by_prompt[prompt].append(entry)

    def default_params(self) -> SamplingParams:
        return self.config.sampling()

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        raise AssertionError("ReplayBackend.complete does not call providers")

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        params = params or self.default_params()
        key = cassette_key(prompt, params)
        with self._lock:
            # exact match first; else the same prompt recorded under other sampling settings
            entries = self._by_key.get(key) or self._by_prompt.get(prompt.fingerprint())
            if not entries:
                raise BackendError(
                    f"replay: {self.path.name} has no recorded answer for this prompt "
                    f"({prompt.describe()}); record it with --record on a real backend"
                )
            slot = key if key in self._by_key else prompt.fingerprint()
            entry = entries[min(self._served[slot], len(entries) - 1)]
            self._served[slot] += 1
        recorded = entry.get("usage")
        usage = (
            Usage.model_validate(recorded)
            if recorded
            else estimate_usage(prompt, entry["text"], self.token_rule)
        )
        return Completion(
            text=entry["text"],
            usage=usage,
            latency_s=0.0,
            cached=False,
            backend=self.backend,
            model=entry.get("model") or self.model,
            finish_reason=entry.get("finish_reason"),
            truncated=bool(entry.get("truncated", False)),
        )
