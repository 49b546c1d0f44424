"""`rover eval --executor ray` writes what the local runner writes, on a local Ray.

Bundled episodes (real simulator truth, QA questions), against the oracle and against
a loopback OpenAI-compatible server answering like a chatty model (markdown, prose). The
metrics must equal the local run's, except per-call latency, which differs between two
local runs too. The server also checks the endpoint budget (calls in flight, counted at
the server, never above --calls-in-flight however many Ray workers run) and where the
API key came from (the workers' environment, never a task argument or a file).
"""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rover.cli import app
from rover.vlm.testing import OpenAICompatServer

from .conftest import WORKER_KEY

runner = CliRunner()


def _eval(out: Path, *args: str, limit: int = 2) -> str:
    res = runner.invoke(
        app,
        ["eval", "--dataset", "bundled", "--limit", str(limit), "--no-cache", "--out", str(out)]
        + list(args),
        catch_exceptions=False,
    )
    assert res.exit_code == 0, res.output
    return res.output


def _without_latency(obj):
    if isinstance(obj, dict):
        return {k: _without_latency(v) for k, v in obj.items() if k != "latency_s"}
    if isinstance(obj, list):
        return [_without_latency(v) for v in obj]
    return obj


def _metrics(out: Path) -> dict:
    return _without_latency(json.loads((out / "metrics.json").read_text()))


def _stage_files(out: Path) -> list[str]:
    return sorted(
        str(p.relative_to(out))
        for d in ("traces", "judgements", "qa", "episodes", "frames")
        for p in (out / d).rglob("*")
        if p.is_file()
    )


def test_oracle_eval_on_ray_equals_local(tmp_path, ray_session) -> None:
    common = ("--backend", "oracle", "--methods", "rover,gvl", "--jitter", "5")
    _eval(tmp_path / "local", *common)
    _eval(tmp_path / "ray", *common, "--executor", "ray")
    local, ray_m = _metrics(tmp_path / "local"), _metrics(tmp_path / "ray")
    assert ray_m["counts"]["traces"] == 4 and ray_m["counts"]["failed"] == 0
    assert ray_m == local
    assert _stage_files(tmp_path / "ray") == _stage_files(tmp_path / "local")
    # resume: a lost judgement is redone from the saved trace alone, on a worker
    lost = next((tmp_path / "ray" / "judgements").rglob("*.json"))
    lost.unlink()
    _eval(tmp_path / "ray", *common, "--executor", "ray", "--resume")
    assert lost.exists() and _metrics(tmp_path / "ray") == local


def _chatty(body: dict) -> str:
    """Replies that depend only on the request, worded like a real model's."""
    text = "\n".join(
        p.get("text", "") if isinstance(p, dict) else str(p)
        for m in body["messages"]
        for p in (m["content"] if isinstance(m["content"], list) else [m["content"]])
    )
    images = sum(
        1
        for m in body["messages"]
        if isinstance(m["content"], list)
        for p in m["content"]
        if p.get("type") == "image_url"
    )
    salt = int(hashlib.sha256(text.encode()).hexdigest()[:4], 16)
    if "Ground-truth simulator state" in text:
        return "**Verdict:** true\n\nTrue statements: the gripper is open\nFalse statements: none"
    if "Question:" in text:
        frame = re.findall(r"^Frame (\d+):", text, re.M)
        return f"Answer: yes\nFrame: {frame[len(frame) // 2]}" if frame else "Answer: no"
    pct = min(100, 12 * images + salt % 7)
    return (
        "Sure! Looking at the latest frame:\n\n"
        "**Frame description:** The gripper is open and the robot is near the cube.\n"
        f"**Task completion percentage:** {pct}%\n"
        f"**Subtask completion percentage:** {pct}%"
    )


def test_loopback_eval_on_ray_equals_local_within_the_endpoint_budget(
    tmp_path, ray_session
) -> None:
    with OpenAICompatServer() as server:
        server.answer = _chatty
        spec = f"openai:test-model@{server.base_url}"
        common = (
            "--backend", spec, "--methods", "rover,temporal-concat",
            "--judge", spec, "--answerer", spec,
        )  # fmt: skip
        _eval(tmp_path / "local", *common, limit=1)
        local_keys = set(server.keys_seen)
        server.keys_seen.clear()
        server.max_in_flight = 0
        _eval(tmp_path / "ray", *common, "--executor", "ray", "--calls-in-flight", "1", limit=1)
        assert server.max_in_flight == 1  # two units on Ray workers, one call at a time
        ray_keys = set(server.keys_seen)
    local, ray_m = _metrics(tmp_path / "local"), _metrics(tmp_path / "ray")
    assert ray_m["counts"]["traces"] == 2 and ray_m["counts"]["failed"] == 0
    assert ray_m == local
    # the key reached the server from the workers' own environment, not from this process
    assert any(WORKER_KEY in k for k in ray_keys) and not any(WORKER_KEY in k for k in local_keys)
    for path in (tmp_path / "ray").rglob("*"):
        if path.is_file():
            assert WORKER_KEY.encode() not in path.read_bytes(), path
    logs = Path("/tmp/ray/session_latest/logs")  # every Ray process's log of this session
    assert logs.is_dir()
    for path in logs.rglob("*"):
        if path.is_file():
            assert WORKER_KEY.encode() not in path.read_bytes(), path


def test_ready_vlm_objects_are_refused_on_a_remote_executor(tmp_path, ray_session) -> None:
    from rover.errors import InputError
    from rover.eval.runner import EvalOptions, prepare_run
    from rover.exec.ray_cluster import RayExecutor
    from rover.sim import bundled_dataset_path

    opts = EvalOptions(
        dataset=bundled_dataset_path(), methods=["gvl"], backends=["mine"], out=tmp_path / "r"
    )
    with pytest.raises(InputError, match="ready VLM objects"):
        prepare_run(opts, vlms={"mine": object()}, executor=RayExecutor())
