"""`rover watch` as a user runs it: a real subprocess following a folder that another real
subprocess writes frames into (partly written files included), replaying a cassette that a
chatty scripted model recorded — replay matches prompts exactly, so a frame read half
written, out of order or twice would miss."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from PIL import Image

from rover.methods.trace import Trace
from rover.stream import RoverStream
from rover.stream.folder import FolderFrames
from rover.vlm.cassette import CassetteWriter, RecordingVLM

TASK = "pick the can and place it in the bin"

# writes each frame in two halves with a pause between (a non-atomic camera writer),
# plus a hidden temp file that must be ignored
WRITER = r"""
import sys, time, pathlib
src, dst, pause = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]), float(sys.argv[3])
for p in sorted(src.glob("*.png")):
    data = p.read_bytes()
    (dst / ".incoming.png").write_bytes(data[:10])
    with open(dst / p.name, "wb") as f:
        f.write(data[: len(data) // 2]); f.flush()
        time.sleep(pause)
        f.write(data[len(data) // 2 :])
    time.sleep(pause)
"""


@pytest.fixture
def frames_dir(tmp_path, make_episode):
    src = tmp_path / "src"
    src.mkdir()
    for t, arr in enumerate(make_episode(14, size=48).views["left"]):
        Image.fromarray(arr).save(src / f"cam_{t:04d}.png")
    return src


async def record(src, cassette, scripted, chatty, count=None) -> Trace:
    """The cassette: the chatty model on the same frames, pushed through a stream."""
    stream = RoverStream(TASK, RecordingVLM(scripted(chatty), CassetteWriter(cassette)))
    for i, p in enumerate(sorted(src.glob("*.png"))[:count]):
        est = await stream.push(np.asarray(Image.open(p).convert("RGB")), index=i)
        if est.complete:
            break
    return await stream.trace()


def watch_cmd(folder, cassette, out, *extra: str) -> list[str]:
    return [
        sys.executable, "-m", "rover.cli", "watch", str(folder), "--task", TASK,
        "--backend", f"replay:{cassette}", "--out", str(out), "--poll", "0.05", *extra,
    ]  # fmt: skip


def env() -> dict[str, str]:
    e = {k: v for k, v in os.environ.items() if k != "ROVER_BACKEND"}
    e["COLUMNS"] = "200"  # the status line must fit 80 columns on its own
    return e


async def test_watch_follows_a_folder_being_written_until_complete(
    tmp_path, frames_dir, scripted, chatty
):
    cassette = tmp_path / "c.jsonl"
    expected = await record(frames_dir, cassette, scripted, chatty)
    assert expected.tree.outcome == "complete" and expected.num_frames < 14
    cam = tmp_path / "cam"
    cam.mkdir()
    out = tmp_path / "live.json"
    watcher = subprocess.Popen(
        watch_cmd(cam, cassette, out, "--idle-timeout", "60"),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env(),
    )  # fmt: skip
    writer = subprocess.Popen([sys.executable, "-c", WRITER, str(frames_dir), str(cam), "0.15"])
    try:
        stdout, stderr = watcher.communicate(timeout=120)
    finally:
        writer.kill()
        writer.wait()
    assert watcher.returncode == 0, stderr
    assert "stopped: task complete" in stdout and f"trace written to {out}" in stdout
    live = Trace.load(out)
    assert live.num_frames == expected.num_frames  # stopped at completion, mid-folder
    assert live.frame_indices == list(range(live.num_frames))  # file numbers, in order
    assert [c.response for c in live.calls] == [c.response for c in expected.calls]
    assert live.progress() == expected.progress() and live.tree.outcome == "complete"
    status = [ln for ln in stderr.splitlines() if " frames [" in ln]
    assert len(status) == live.num_frames  # not a terminal: one status line per frame
    assert all(len(ln) <= 80 for ln in status), status
    assert status[-1].rstrip().endswith("done") and "100.0%" in status[-1]


async def test_watch_stops_when_idle_and_on_ctrl_c(tmp_path, frames_dir, scripted, chatty):
    cassette = tmp_path / "c.jsonl"
    await record(frames_dir, cassette, scripted, chatty, count=4)
    cam = tmp_path / "cam"
    cam.mkdir()
    for p in sorted(frames_dir.glob("*.png"))[:3]:
        (cam / p.name).write_bytes(p.read_bytes())
    (cam / "notes.txt").write_text("not a frame")
    out = tmp_path / "idle.json"
    res = subprocess.run(
        watch_cmd(cam, cassette, out, "--idle-timeout", "1"),
        capture_output=True, text=True, timeout=120, env=env(),
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "stopped: no new frame for 1 s" in res.stdout
    assert Trace.load(out).num_frames == 3

    # Ctrl-C: stops after the frame in hand and still writes the trace
    out2 = tmp_path / "int.json"
    watcher = subprocess.Popen(
        watch_cmd(cam, cassette, out2, "--idle-timeout", "60"),
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env(),
    )  # fmt: skip
    deadline = time.monotonic() + 60
    while not out2.exists() and time.monotonic() < deadline:
        line = watcher.stderr.readline()
        if "   3 frames [" in line:
            break
    watcher.send_signal(signal.SIGINT)
    stdout, stderr = watcher.communicate(timeout=60)
    assert watcher.returncode == 0, stderr
    assert "stopped: interrupted" in stdout
    assert json.loads(out2.read_text())["num_frames"] == 3


def test_folder_skips_partial_hidden_and_late_files(tmp_path, make_episode):
    frames = make_episode(3, size=16).views["left"]
    folder = FolderFrames(tmp_path)
    Image.fromarray(frames[0]).save(tmp_path / "f_2.png")
    data = (tmp_path / "f_2.png").read_bytes()
    (tmp_path / "f_10.png").write_bytes(data[: len(data) // 2])  # half written
    (tmp_path / ".f_11.png").write_bytes(data)  # hidden: a writer's temp name
    assert folder.poll() == []  # nothing is taken on first sight
    got = folder.poll()
    assert [f.path.name for f in got] == ["f_2.png"] and got[0].index == 2
    assert np.array_equal(got[0].pixels, frames[0])
    assert folder.poll() == []  # f_10 is stable but undecodable: still waiting
    Image.fromarray(frames[1]).save(tmp_path / "f_10.png")
    folder.poll()
    got = folder.poll()
    assert [(f.path.name, f.index) for f in got] == [("f_10.png", 10)]  # 10 after 2
    Image.fromarray(frames[2]).save(tmp_path / "f_3.png")  # late: sorts before f_10
    assert folder.poll() == [] and folder.poll() == [] and folder.skipped == ["f_3.png"]


def test_bad_watch_input_is_one_line(tmp_path):
    cmd = [sys.executable, "-m", "rover.cli", "watch"]
    for args, msg in [
        ([str(tmp_path / "nope"), "--task", "x", "--backend", "openai:m"], "not a folder"),
        ([str(tmp_path), "--task", "x", "--backend", "oracle"], "ground truth"),
        ([str(tmp_path), "--backend", "openai:m"], "needs the task"),
        ([str(tmp_path), "--task", "x", "--idle-timeout", "0"], "must be positive"),
    ]:
        res = subprocess.run([*cmd, *args], capture_output=True, text=True, env=env(), timeout=60)
        assert res.returncode == 2 and msg in res.stderr, res.stderr
        assert len(res.stderr.strip().splitlines()) == 1


def test_status_line_is_literal_safe_and_fits():
    from rover.commands.watch import status_line
    from rover.stream.rover_stream import FrameEstimate

    hostile = ["[bold red]grab[/] \x1b]0;pwned\x07 the can", "x" * 200]
    est = FrameEstimate(position=9, index=9, progress=45.0, subtask_path=hostile, calls=1)
    text = status_line(est, 10, 31)
    assert len(text.plain) <= 80 and "\x1b" not in text.plain and "\x07" not in text.plain
    assert text.plain.startswith("  10 frames [#####       ]  45.0%  ")
    assert text.plain.endswith("  31 calls") and "xxx" in text.plain  # innermost kept
    short = status_line(FrameEstimate(0, 0, 100.0, ["[b]a[/b]"], complete=True), 1, 2)
    assert "[b]a[/b]" in short.plain and short.plain.endswith("2 calls  done")
