"""`rover annotate`: per-frame parquet over whole datasets, resumable without repeated calls."""

from __future__ import annotations

import asyncio
import hashlib
import json
import os
import signal
import subprocess
import sys
import threading

import pytest
from typer.testing import CliRunner

from rover.annotate import AnnotateOptions, plan_annotation, run_annotate
from rover.cli import app
from rover.errors import InputError
from rover.io.source import open_source
from rover.vlm.testing import OpenAICompatServer
from rover.vlm.types import Completion, Usage

from .conftest import model_like_answer, write_lerobot_v3

pq = pytest.importorskip("pyarrow.parquet")

LENGTHS = (12, 9, 7)


def _fingerprint(body: dict) -> str:
    return hashlib.sha256(json.dumps(body.get("messages"), sort_keys=True).encode()).hexdigest()


def _args(root, out, server, cache) -> list[str]:
    return [
        "annotate",
        f"lerobot:{root}",
        "--method",
        "rover",
        "--backend",
        f"openai:test-model@{server.base_url}",
        "--out",
        str(out),
        "--cache",
        str(cache),
        "--concurrency",
        "1",
        "--calls-in-flight",
        "1",
        "--max-retries",
        "0",
    ]


@pytest.fixture(scope="module")
def lerobot3(tmp_path_factory):
    return write_lerobot_v3(tmp_path_factory.mktemp("lr") / "koch", lengths=LENGTHS)


def _check_frames_table(path, lengths=LENGTHS):
    rows = pq.read_table(path).to_pylist()
    assert len(rows) == sum(lengths)  # one row per frame
    for ep, n in enumerate(lengths):
        mine = [r for r in rows if r["episode_index"] == ep]
        assert [r["frame_index"] for r in mine] == list(range(n))  # no gaps
        assert all(0 <= r["progress"] <= 100 for r in mine)
        assert all(isinstance(r["subtask_path"], list) for r in mine)
    return rows


def test_annotate_lerobot_writes_parquet_and_resumes_after_kill(lerobot3, tmp_path):
    # an uninterrupted run: how many calls the whole annotation takes
    with OpenAICompatServer() as server:
        server.answer = model_like_answer
        args = _args(lerobot3, tmp_path / "full", server, tmp_path / "full.sqlite")
        res = CliRunner().invoke(app, args, catch_exceptions=False)
        assert res.exit_code == 0, res.output
        total = server.count
    rows = _check_frames_table(tmp_path / "full" / "frames.parquet")
    assert rows[1]["description"] == "The gripper is near the object."
    assert {r["method"] for r in rows} == {"rover"} and {r["model"] for r in rows} == {"test-model"}
    episodes = pq.read_table(tmp_path / "full" / "episodes.parquet").to_pylist()
    assert [e["episode_index"] for e in episodes] == [0, 1, 2]
    assert sum(e["calls"] - e["cached_calls"] for e in episodes) == total > len(LENGTHS)
    assert all(e["success_threshold"] == 95.0 and e["voc"] is not None for e in episodes)

    # the same annotation, killed (SIGKILL) when the 7th call arrives, then resumed
    out, cache = tmp_path / "killed", tmp_path / "killed.sqlite"
    kill_at = 7
    with OpenAICompatServer() as server:
        proc: dict = {}
        answered: list[str] = []
        lock = threading.Lock()

        def answer(body: dict) -> str:
            with lock:
                if len(answered) + 1 == kill_at:
                    os.kill(proc["p"].pid, signal.SIGKILL)
                    proc["p"].wait(timeout=60)
                    return "never delivered"
                answered.append(_fingerprint(body))
            return model_like_answer(body)

        server.answer = answer
        cmd = [sys.executable, "-m", "rover.cli", *_args(lerobot3, out, server, cache)]
        proc["p"] = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        proc["p"].wait(timeout=300)
        assert proc["p"].returncode == -signal.SIGKILL
        assert len(answered) == kill_at - 1
        first_run = server.count

        server.answer = model_like_answer
        res = CliRunner().invoke(app, [*_args(lerobot3, out, server, cache), "--resume"])
        assert res.exit_code == 0, res.output
        resumed = [_fingerprint(r) for r in server.requests[first_run:]]
    assert not set(resumed) & set(answered)  # no answered call asked again
    assert len(answered) + len(resumed) == total
    _check_frames_table(out / "frames.parquet")


def test_dry_run_counts_calls_and_spends_nothing(lerobot3, tmp_path):
    with OpenAICompatServer() as server:
        server.answer = model_like_answer
        args = [*_args(lerobot3, tmp_path / "dry", server, tmp_path / "c.sqlite"), "--dry-run"]
        res = CliRunner().invoke(app, args, catch_exceptions=False)
        assert res.exit_code == 0, res.output
        assert server.count == 0
    assert not (tmp_path / "dry").exists()
    assert "3 episode(s) to annotate" in res.output
    # the stand-in never decomposes: ROVER asks once per frame of every episode
    assert f"calls: {sum(LENGTHS)}" in res.output
    assert "estimated tokens:" in res.output and "image rule openai-high" in res.output


def test_in_place_subset_and_refusals(lerobot3, tmp_path):
    with OpenAICompatServer() as server:
        server.answer = model_like_answer
        base = _args(lerobot3, tmp_path / "sub", server, tmp_path / "c.sqlite")
        res = CliRunner().invoke(app, [*base, "--episodes", "2,episode_000000", "--in-place"])
        assert res.exit_code == 0, res.output
        rows = pq.read_table(lerobot3 / "rover_progress.parquet").to_pylist()
        assert sorted({r["episode_index"] for r in rows}) == [0, 2]
        # LeRobot's dataset-wide index: episode 2 starts after episodes 0 and 1
        assert [r["index"] for r in rows if r["episode_index"] == 2][0] == 12 + 9
        assert all(r["progress_sparse"] == pytest.approx(r["progress"] / 100) for r in rows)
        # an existing annotation is not overwritten or mixed with other settings
        res = CliRunner().invoke(app, base)
        assert isinstance(res.exception, InputError) and "--resume" in str(res.exception)
        res = CliRunner().invoke(app, [*base, "--resume", "--frames", "5"])
        assert "other settings (frames)" in str(res.exception)
        assert server.count > 0
    (lerobot3 / "rover_progress.parquet").unlink()


class _ScriptVLM:
    """The in-process scripted VLM: rising progress, never decomposes."""

    backend, model = "scripted", "script"

    def __init__(self) -> None:
        self.calls = 0

    def bind(self, episode):
        return self

    async def complete(self, prompt, params=None) -> Completion:
        self.calls += 1
        pos = prompt.meta.positions[-1] if prompt.meta.positions else 0
        text = f"Frame description: step {pos}\nSubtask completion percentage: {10 * pos}%"
        return Completion(text=text, usage=Usage(prompt_tokens=5, completion_tokens=2))


def test_annotate_other_sources_with_sample(tmp_path, make_rlds, make_robomimic):
    rlds = make_rlds(tmp_path / "rlds", shards=((6, 5), (4,)), image_keys=("image",))
    vlm = _ScriptVLM()
    opts = AnnotateOptions(
        source=f"rlds:{rlds}", out=tmp_path / "a", method="rover", sample=2, seed=1, vlm=vlm
    )
    result = asyncio.run(run_annotate(opts))
    assert result.annotated == 2 and not result.failed and vlm.calls == result.calls
    episodes = pq.read_table(result.episodes_path).to_pylist()
    assert len(episodes) == 2 and all(0 <= e["episode_index"] < 3 for e in episodes)
    with pytest.raises(InputError, match="clip-value needs --model-path"):
        plan_annotation(
            AnnotateOptions(source=f"rlds:{rlds}", out=tmp_path / "c", method="clip-value")
        )
    h5 = make_robomimic(tmp_path / "demo.hdf5", lengths=(5, 4), task="")
    with pytest.raises(InputError, match="carries no task description"):
        asyncio.run(run_annotate(AnnotateOptions(source=f"hdf5:{h5}", out=tmp_path / "b")))
    opts = AnnotateOptions(source=f"hdf5:{h5}", out=tmp_path / "b", task="lift", vlm=_ScriptVLM())
    result = asyncio.run(run_annotate(opts))
    _check_frames_table(result.frames_path, lengths=(5, 4))


def test_annotate_rover_dataset_with_the_oracle(tmp_path):
    from rover.sim import bundled_dataset_path

    out = tmp_path / "oracle"
    args = ["annotate", str(bundled_dataset_path()), "--backend", "oracle", "--out", str(out)]
    res = CliRunner().invoke(app, [*args, "--sample", "2", "--frames", "8", "--method", "gvl"])
    assert res.exit_code == 0, res.output
    assert "ORACLE" in res.output
    episodes = pq.read_table(out / "episodes.parquet").to_pylist()
    assert len(episodes) == 2 and all(e["backend"] == "oracle" for e in episodes)
    # the oracle follows simulator truth: final progress is the last sampled frame's truth
    reader = open_source(bundled_dataset_path())
    for e in episodes:
        truth = reader.read(e["episode_id"], frames=8).truth.progress[-1]
        assert e["final_progress"] == pytest.approx(100 * truth, abs=0.5)
        assert e["success"] == (e["final_progress"] >= 95)
    rows = pq.read_table(out / "frames.parquet").to_pylist()
    assert len(rows) == 16 and all(r["description"] for r in rows[1:8])
