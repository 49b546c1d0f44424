"""Typer options shared by every command that talks to a VLM, and the config they build.

A command declares the options it wants with these aliases and passes their values to
`config_from_options`, which drops the ones left unset so `BackendConfig`'s defaults
apply::

    from rover.vlm import cli_options as vo

    def reason(
        video: str,
        vlm: vo.VLMOpt = "oracle",
        cache: vo.CacheOpt = None,
        no_cache: vo.NoCacheOpt = False,
        record: vo.RecordOpt = None,
        concurrency: vo.ConcurrencyOpt = None,
        timeout: vo.TimeoutOpt = None,
        max_retries: vo.MaxRetriesOpt = None,
        api_key_env: vo.ApiKeyEnvOpt = None,
        detail: vo.DetailOpt = None,
        token_rule: vo.TokenRuleOpt = None,
        max_side: vo.ImageMaxSideOpt = None,
        temperature: vo.TemperatureOpt = None,
        max_tokens: vo.MaxTokensOpt = None,
        device: vo.DeviceOpt = None,
    ) -> None:
        config = vo.config_from_options(
            cache=cache, no_cache=no_cache, record=record, concurrency=concurrency,
            timeout=timeout, max_retries=max_retries, api_key_env=api_key_env,
            detail=detail, token_rule=token_rule, max_side=max_side,
            temperature=temperature, max_tokens=max_tokens, device=device,
        )
        model = load_vlm(vlm, config)

Oracle knobs (`seed`, `flip_prob`, `jitter`) and any other `BackendConfig` field can be
passed to `config_from_options` under their field names.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from pydantic import ValidationError

from rover.errors import InputError
from rover.vlm.config import BackendConfig

VLM_HELP = (
    "VLM spec: openai:<model>[@<url>[,<url>...]], gemini:<model>, hf:<path>, oracle, replay:<file>"
)

VLMOpt = Annotated[str, typer.Option("--vlm", help=VLM_HELP)]
CacheOpt = Annotated[
    Path | None,
    typer.Option(
        "--cache", help="Response cache file (default: $ROVER_CACHE_DIR or ~/.cache/rover)."
    ),
]
NoCacheOpt = Annotated[
    bool, typer.Option("--no-cache", help="Neither read nor write the response cache.")
]
RecordOpt = Annotated[
    Path | None,
    typer.Option("--record", help="Append every completion to this cassette (for replay:FILE)."),
]
ConcurrencyOpt = Annotated[
    int | None, typer.Option("--concurrency", help="VLM calls in flight at once (default 8).")
]
TimeoutOpt = Annotated[
    float | None,
    typer.Option("--timeout", help="Seconds per VLM call attempt (default 60; 10 to connect)."),
]
MaxRetriesOpt = Annotated[
    int | None,
    typer.Option("--max-retries", help="Retries on rate limits, 5xx and timeouts (default 6)."),
]
ApiKeyEnvOpt = Annotated[
    str | None,
    typer.Option(
        "--api-key-env",
        help="Environment variable holding the API key (default OPENAI_API_KEY / GEMINI_API_KEY).",
    ),
]
DetailOpt = Annotated[
    str | None, typer.Option("--detail", help="OpenAI image detail: auto, low or high.")
]
TokenRuleOpt = Annotated[
    str | None,
    typer.Option(
        "--token-rule", help="Image-token rule for estimates: openai-high, openai-low, gemini."
    ),
]
ImageMaxSideOpt = Annotated[
    int | None,
    typer.Option("--image-max-side", help="Downscale images so the long side is at most this."),
]
TemperatureOpt = Annotated[
    float | None, typer.Option("--temperature", help="Sampling temperature (default 0).")
]
MaxTokensOpt = Annotated[
    int | None,
    typer.Option(
        "--max-tokens",
        help="Most tokens per answer for every call (default: sized to what each call asks).",
    ),
]
DeviceOpt = Annotated[
    str | None, typer.Option("--device", help="hf backend device: cpu, cuda, cuda:1 ...")
]


def resolve_backend(given: str | None) -> str:
    """The backend spec a command uses: `--backend`, else `ROVER_BACKEND` or the config file.

    Raises:
        InputError: none of them is set (one line naming the choices).
    """
    from rover.vlm.config import BACKEND_ENV, config_file_path, default_backend

    if given is not None and given.strip():
        return given.strip()
    chosen = default_backend()
    if chosen:
        return chosen
    raise InputError(
        "no VLM backend chosen: pass --backend SPEC ("
        + VLM_HELP.removeprefix("VLM spec: ")
        + f"), or set {BACKEND_ENV} or 'backend = \"SPEC\"' in {config_file_path()}"
    )


# option name -> BackendConfig field, where they differ
_RENAMES = {
    "cache": "cache_path",
    "timeout": "timeout_s",
    "max_side": "image_max_side",
    "quality": "image_quality",
    "format": "image_format",
}


_OPTION_OF = {field: option for option, field in _RENAMES.items()}


def config_from_options(**options: Any) -> BackendConfig:
    """A BackendConfig from command options; None (and False for flags) means "default".

    Raises:
        InputError: an option value the config rejects (one line naming the option).
    """
    fields: dict[str, Any] = {}
    for name, value in options.items():
        if value is None:
            continue
        fields[_RENAMES.get(name, name)] = value
    try:
        return BackendConfig(**fields)
    except ValidationError as exc:
        err = exc.errors()[0]
        where = ".".join(str(x) for x in err["loc"]) or "option"
        where = _OPTION_OF.get(where, where)  # name the option the user typed, not the field
        raise InputError(f"--{where.replace('_', '-')}: {err['msg']}") from None
