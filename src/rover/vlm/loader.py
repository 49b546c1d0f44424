"""`load_vlm(spec)`: turn a spec string into a ready backend.

Spec strings: `openai:<model>[@<base_url>]` (several comma-separated URLs: a pool of
replicas, see `rover.vlm.pool`), `gemini:<model>[@<base_url>]`, `hf:<path>`,
`oracle`, `replay:<cassette>`. Each provider module (and its SDK) is imported only when
its spec is used, so `import rover.vlm` stays cheap and missing extras fail with an
install hint instead of an ImportError.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from rover.errors import BackendError, InputError
from rover.vlm.config import BackendConfig

if TYPE_CHECKING:
    from rover.vlm.types import VLM

SPEC_FORMS = (
    "openai:<model>[@<base_url>[,<base_url>...]]",
    "gemini:<model>[@<base_url>]",
    "hf:<path>",
    "oracle",
    "replay:<cassette.jsonl>",
)


def split_model_url(rest: str) -> tuple[str, str | None]:
    """`"qwen@http://host:8000/v1"` -> ("qwen", "http://host:8000/v1"); no URL -> None.

    Raises:
        InputError: what follows an '@' looks like a server but has no scheme
            (`m@127.0.0.1:8000/v1`): guessing would send the key to the public API.
    """
    lowered = rest.lower()
    for scheme in ("@http://", "@https://"):
        at = lowered.find(scheme)
        if at >= 0:
            return rest[:at], rest[at + 1 :]
    at = rest.rfind("@")
    if at >= 0:
        after = rest[at + 1 :]
        if "://" in after or _looks_like_host(after):
            raise InputError(
                f"{rest!r}: the server after '@' needs an explicit scheme: "
                f"{rest[:at]}@http://{after.split('://')[-1]} (or https://)"
            )
    return rest, None


def _looks_like_host(text: str) -> bool:
    """'127.0.0.1:8000/v1', 'localhost', 'host.example:443': a server, not part of a name."""
    head = text.split("/", 1)[0]
    return bool(head) and ("/" in text or ":" in head or "." in head or head.lower() == "localhost")


def parse_spec(spec: str) -> tuple[str, str, str | None]:
    """(backend, model-or-path, base_url) for a spec string; InputError when malformed."""
    spec = spec.strip()
    name, sep, rest = spec.partition(":")
    name = name.lower()
    if name == "oracle" and not rest:
        return "oracle", "oracle", None
    if name not in ("openai", "gemini", "hf", "replay"):
        raise InputError(f"unknown VLM spec {spec!r}; use one of: {', '.join(SPEC_FORMS)}")
    if not sep or not rest.strip():
        what = "a path" if name in ("hf", "replay") else "a model name"
        raise InputError(f"VLM spec {spec!r} needs {what} after '{name}:'")
    if name in ("openai", "gemini"):
        model, url = split_model_url(rest.strip())
        if not model:
            raise InputError(f"VLM spec {spec!r} needs a model name before '@'")
        return name, model, url
    return name, rest.strip(), None


def load_vlm(spec: str, config: BackendConfig | None = None) -> VLM:
    """The VLM for `spec`, configured by `config` (defaults when None).

    With `config.record` set, the backend is wrapped so every completion is also appended
    to that cassette, whichever backend it is.

    Raises:
        InputError: malformed spec, missing model folder or cassette.
        MissingExtraError: the backend's SDK is not installed (the message says what to install).
        BackendError: no API key where one is required.
    """
    config = config or BackendConfig()
    backend, model, url = parse_spec(spec)
    vlm: VLM
    if backend == "openai":
        from rover.vlm.openai_backend import OpenAIBackend

        vlm = OpenAIBackend(model, url, config)
    elif backend == "gemini":
        from rover.vlm.gemini_backend import GeminiBackend

        vlm = GeminiBackend(model, url, config)
    elif backend == "hf":
        from rover.vlm.hf_backend import HFBackend

        vlm = HFBackend(model, config)
    elif backend == "replay":
        from rover.vlm.cassette import ReplayBackend

        vlm = ReplayBackend(model, config)
    else:
        vlm = _load_oracle(config)
    open_cache = getattr(vlm, "_response_cache", None)
    if open_cache is not None:
        open_cache()  # an unusable --cache fails now, before any decoding or paid call
    if config.record is not None:
        from rover.vlm.cassette import CassetteWriter, RecordingVLM

        vlm = RecordingVLM(vlm, CassetteWriter(config.record))
    return vlm


def _load_oracle(config: BackendConfig) -> VLM:
    try:
        module = importlib.import_module("rover.vlm.oracle")
    except ModuleNotFoundError as exc:
        if exc.name != "rover.vlm.oracle":
            raise
        raise BackendError("the oracle backend is not available in this install") from exc
    return module.OracleBackend(config)
