"""`rover reason` end to end: real MP4 / frame-folder / dataset inputs, replay and oracle."""

from __future__ import annotations

import asyncio
import os
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from rover.cli import app
from rover.io.dataset import write_episode
from rover.io.source import load_episode
from rover.io.video import write_video
from rover.methods import Trace, get_method
from rover.vlm.cassette import CassetteWriter, RecordingVLM
from rover.vlm.types import Prompt

TASK = "pick the can and place it in the bin"


def script(p: Prompt) -> str:
    m = p.meta
    if m.kind == "rover.parent":
        return "Task complete"
    if not m.subtask_path:
        return "Frame description: the can is on the table\nThe robot needs to: grasp the can"
    pos = m.positions[-1]
    return f"Frame description: frame {pos}\nSubtask completion percentage: {20 * pos}%"


async def record(spec: str, cassette: Path, scripted, frames: int | None) -> Trace:
    """Record what a scripted model answers on the episode the CLI will load."""
    ep = load_episode(spec, frames=frames, size=256, task=TASK)
    vlm = RecordingVLM(scripted(script), CassetteWriter(cassette))
    return await get_method("rover").run(ep, vlm)


@pytest.fixture
def clip(tmp_path, make_episode):
    frames = make_episode(12, size=64).views["left"]
    path = tmp_path / "clip.mp4"
    write_video(path, frames, fps=10)
    return path, frames


def test_reason_mp4_with_replay(tmp_path, clip, scripted):
    path, _ = clip
    cassette = tmp_path / "run.jsonl"
    recorded = asyncio.run(record(str(path), cassette, scripted, frames=6))
    out = tmp_path / "trace.json"
    args = ["reason", str(path), "--task", TASK, "--method", "rover", "--frames", "6"]
    res = CliRunner().invoke(app, [*args, "--backend", f"replay:{cassette}", "--out", str(out)])
    assert res.exit_code == 0, res.output
    trace = Trace.load(out)
    assert trace.backend == "replay" and not trace.oracle
    assert trace.frame_indices == [0, 2, 4, 7, 9, 11]  # 6 of 12, first and last kept
    assert trace.progress() == recorded.progress()
    assert trace.totals.calls == recorded.totals.calls
    assert f"trace written to {out}" in res.output
    assert "ORACLE" not in res.output


def test_reason_frame_folder_with_gaps(tmp_path, make_episode, scripted):
    frames = make_episode(5, size=48).views["left"]
    folder = tmp_path / "frames"
    folder.mkdir()
    numbers = [0, 2, 6, 12, 30]  # frame_12 sorts after frame_6; gaps allowed
    for arr, n in zip(frames, numbers, strict=True):
        Image.fromarray(arr).save(folder / f"frame_{n}.png")
    cassette = tmp_path / "c.jsonl"
    asyncio.run(record(str(folder), cassette, scripted, frames=None))
    out = tmp_path / "t.json"
    res = CliRunner().invoke(
        app,
        ["reason", str(folder), "--task", TASK, "--backend", f"replay:{cassette}", "-o", str(out)],
    )
    assert res.exit_code == 0, res.output
    trace = Trace.load(out)
    assert trace.frame_indices == numbers
    assert [f.index for f in trace.frames] == numbers
    assert trace.frames[3].description == "frame 3"
    assert trace.tree.children[0].first_frame == 0


def test_reason_dataset_episode_with_oracle(tmp_path, make_episode):
    ep_dir = write_episode(tmp_path / "ds", make_episode(20, size=64))
    out = tmp_path / "gvl.json"
    res = CliRunner().invoke(
        app,
        ["reason", str(ep_dir), "--method", "gvl", "--frames", "8", "--backend", "oracle"]
        + ["--out", str(out)],
    )
    assert res.exit_code == 0, res.output
    assert "ORACLE" in res.output
    trace = Trace.load(out)
    assert trace.oracle and trace.task == TASK and trace.num_frames == 8
    assert trace.totals.calls == 7
    assert trace.progress()[-1] == pytest.approx(100, abs=1)


def test_reason_errors_are_one_line(tmp_path, clip):
    path, _ = clip
    cmd = [sys.executable, "-m", "rover.cli", "reason", str(path), "--out", str(tmp_path / "x")]
    env = {k: v for k, v in os.environ.items() if k != "ROVER_BACKEND"}
    env["ROVER_CONFIG"] = str(tmp_path / "no-config.toml")

    def run(*extra: str) -> subprocess.CompletedProcess:
        return subprocess.run([*cmd, *extra], capture_output=True, text=True, timeout=120, env=env)

    # no backend given and none configured: one line naming the choices, nothing decoded
    res = run("--task", TASK)
    assert res.returncode == 2 and "no VLM backend chosen" in res.stderr
    assert "openai:<model>" in res.stderr and "ROVER_BACKEND" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    # the oracle on a real video: refused by the one oracle rule, one line
    res = run("--task", TASK, "--backend", "oracle")
    assert res.returncode == 2
    assert "the oracle answers from simulator ground truth" in res.stderr
    assert "Traceback" not in res.stderr and len(res.stderr.strip().splitlines()) == 1
    res = run("--backend", "oracle")
    assert res.returncode == 2 and "pass --task" in res.stderr


def test_replayed_oracle_stays_labelled(tmp_path, make_episode):
    ep_dir = write_episode(tmp_path / "ds", make_episode(10, size=64))
    cassette, out = tmp_path / "oracle.jsonl", tmp_path / "r.json"
    base = ["reason", str(ep_dir), "--method", "rover", "--out", str(out)]
    recording = [*base, "--backend", "oracle", "--record", str(cassette)]
    assert CliRunner().invoke(app, recording).exit_code == 0
    recorded = Trace.load(out)
    res = CliRunner().invoke(app, [*base, "--backend", f"replay:{cassette}"])
    assert res.exit_code == 0, res.output
    replayed = Trace.load(out)
    assert replayed.backend == "replay" and replayed.oracle and "ORACLE" in res.output
    assert replayed.progress() == recorded.progress()


def test_default_backend_from_env_or_config_file_and_documented_flags(
    tmp_path, make_episode, monkeypatch
):
    ep_dir = write_episode(tmp_path / "ds", make_episode(8, size=64))
    out = tmp_path / "t.json"
    args = ["reason", str(ep_dir), "--method", "gvl", "--out", str(out)]
    # backends.md documents --temperature and --image-max-side for every VLM command
    flags = ["--temperature", "0.2", "--image-max-side", "32"]
    monkeypatch.setenv("ROVER_CONFIG", str(tmp_path / "config.toml"))
    monkeypatch.setenv("ROVER_BACKEND", "oracle")
    res = CliRunner().invoke(app, [*args, *flags])
    assert res.exit_code == 0, res.output
    assert Trace.load(out).oracle
    monkeypatch.delenv("ROVER_BACKEND")
    res = CliRunner().invoke(app, args)
    assert res.exit_code != 0 and "no VLM backend chosen" in str(res.exception)
    (tmp_path / "config.toml").write_text('backend = "oracle"\n')
    out.unlink()
    assert CliRunner().invoke(app, args).exit_code == 0 and Trace.load(out).oracle
