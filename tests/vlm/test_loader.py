"""Spec strings, the lazy package import, and the shared CLI options."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest
import typer
from typer.testing import CliRunner

from rover.errors import BackendError, InputError
from rover.vlm import BackendConfig, load_vlm, parse_spec
from rover.vlm import cli_options as vo


@pytest.mark.parametrize(
    ("spec", "expected"),
    [
        ("openai:gpt-4o", ("openai", "gpt-4o", None)),
        (
            "openai:Qwen/Qwen2.5-VL-7B@http://localhost:8000/v1",
            ("openai", "Qwen/Qwen2.5-VL-7B", "http://localhost:8000/v1"),
        ),
        (
            "openai:gemini-2.0-flash@https://generativelanguage.googleapis.com/v1beta/openai/",
            (
                "openai",
                "gemini-2.0-flash",
                "https://generativelanguage.googleapis.com/v1beta/openai/",
            ),
        ),
        (
            "openai:qwen2.5vl:7b@http://127.0.0.1:11434/v1",
            ("openai", "qwen2.5vl:7b", "http://127.0.0.1:11434/v1"),
        ),
        ("gemini:gemini-2.5-flash", ("gemini", "gemini-2.5-flash", None)),
        ("hf:/models/Qwen2.5-VL-3B", ("hf", "/models/Qwen2.5-VL-3B", None)),
        ("replay:runs/a.jsonl", ("replay", "runs/a.jsonl", None)),
        (" oracle ", ("oracle", "oracle", None)),
    ],
)
def test_parse_spec(spec, expected):
    assert parse_spec(spec) == expected


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("claude:opus", "unknown VLM spec"),
        ("gpt-4o", "unknown VLM spec"),
        ("openai:", "needs a model name"),
        ("hf:", "needs a path"),
        ("openai:@http://localhost:8000/v1", "model name before"),
    ],
)
def test_bad_specs_are_one_line_input_errors(spec, message):
    with pytest.raises(InputError, match=message) as info:
        load_vlm(spec)
    assert "\n" not in str(info.value)


def test_oracle_spec_loads_the_oracle_module():
    if importlib.util.find_spec("rover.vlm.oracle") is None:
        with pytest.raises(BackendError, match="oracle"):
            load_vlm("oracle")
    else:
        assert load_vlm("oracle", BackendConfig(seed=3)).backend == "oracle"


def test_importing_rover_vlm_loads_no_sdk():
    code = (
        "import sys, rover.vlm, rover.vlm.cli_options\n"
        "heavy = [m for m in sys.modules if m.split('.')[0] in "
        "('openai', 'torch', 'transformers', 'tiktoken', 'httpx', 'httpx2')"
        " or m.startswith('google.genai')]\n"
        "assert not heavy, heavy\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_config_from_options_keeps_defaults_for_unset_values(tmp_path):
    config = vo.config_from_options(
        cache=tmp_path / "c.sqlite", timeout=3.5, concurrency=None, detail="low", flip_prob=0.2
    )
    assert config.cache_path == tmp_path / "c.sqlite"
    assert (config.timeout_s, config.concurrency, config.detail) == (3.5, 8, "low")
    assert config.flip_prob == 0.2
    with pytest.raises(InputError, match="--concurrency"):
        vo.config_from_options(concurrency=0)
    with pytest.raises(InputError, match="--token-rule"):
        vo.config_from_options(token_rule="cheapest")


def test_option_aliases_work_in_a_typer_command(tmp_path):
    app = typer.Typer()
    seen: dict[str, BackendConfig] = {}

    @app.command()
    def ask(
        vlm: vo.VLMOpt = "oracle",
        cache: vo.CacheOpt = None,
        no_cache: vo.NoCacheOpt = False,
        record: vo.RecordOpt = None,
        timeout: vo.TimeoutOpt = None,
        api_key_env: vo.ApiKeyEnvOpt = None,
        max_side: vo.ImageMaxSideOpt = None,
    ) -> None:
        seen["config"] = vo.config_from_options(
            cache=cache,
            no_cache=no_cache,
            record=record,
            timeout=timeout,
            api_key_env=api_key_env,
            max_side=max_side,
        )

    args = ["--no-cache", "--record", str(tmp_path / "r.jsonl"), "--timeout", "9"]
    args += ["--api-key-env", "MY_KEY", "--image-max-side", "256"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    config = seen["config"]
    assert config.no_cache and config.record == Path(tmp_path / "r.jsonl")
    assert (config.timeout_s, config.api_key_env, config.image_max_side) == (9.0, "MY_KEY", 256)
