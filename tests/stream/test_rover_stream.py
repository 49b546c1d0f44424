"""RoverStream: a video pushed frame by frame gives exactly that video's offline trace."""

from __future__ import annotations

import pytest

from rover.errors import InputError
from rover.methods import get_method
from rover.methods.trace import Trace
from rover.stream import RoverStream
from rover.vlm.loader import load_vlm

TASK = "pick the can and place it in the bin"
VOLATILE = {"started_at", "finished_at"}


def comparable(trace: Trace) -> dict:
    """Everything in a trace except timestamps and wall-clock latencies."""
    d = trace.model_dump(mode="json", exclude=VOLATILE)
    for c in d["calls"]:
        c.pop("latency_s")
    d["totals"].pop("latency_s")
    return d


async def stream_video(episode, vlm, **params) -> tuple[Trace, list, RoverStream]:
    stream = RoverStream(episode.task, vlm, bind=episode, episode_id=episode.id, **params)
    estimates = []
    for pos, frame in enumerate(episode.frames()):
        estimates.append(await stream.push(frame, index=episode.frame_indices[pos]))
    return await stream.trace(), estimates, stream


def assert_same_trace(live: Trace, offline: Trace) -> None:
    a, b = comparable(live), comparable(offline)
    for key in b:  # field by field, so a failure names the field
        assert a[key] == b[key], key
    assert a == b


@pytest.mark.parametrize(
    "params",
    [{}, {"window": 5}, {"prev_frame_policy": "on_change"}, {"window": None}, {"max_depth": 1}],
)
async def test_chatty_model_stream_equals_offline(make_episode, scripted, chatty, params):
    ep = make_episode(16)
    offline_vlm, live_vlm = scripted(chatty), scripted(chatty)
    offline = await get_method("rover", **params).run(ep, offline_vlm)
    live, estimates, _ = await stream_video(ep, live_vlm, **params)
    assert_same_trace(live, offline)
    # the model saw the very same prompts, in the same order
    assert [p.fingerprint() for p in live_vlm.prompts] == [
        p.fingerprint() for p in offline_vlm.prompts
    ]
    # the script exercised what it should: a nested line, a re-ask, a parent turn
    assert offline.tree.children[0].children or params.get("max_depth") == 1
    assert offline.totals.parse_retries >= 1
    assert any(c.kind == "rover.parent" for c in offline.calls)
    # calls are charged to the frame that caused them and sum to the trace's
    assert sum(e.calls for e in estimates) == offline.totals.calls
    # the plan never grew here, so the live values are the trace's stitched values
    assert [e.progress for e in estimates] == pytest.approx(offline.progress(), abs=1e-9)


async def test_oracle_stream_equals_offline_and_progress_rises(make_episode):
    ep = make_episode(20)
    offline = await get_method("rover").run(ep, load_vlm("oracle"))
    live, estimates, stream = await stream_video(ep, load_vlm("oracle"))
    assert live.oracle and offline.oracle
    assert_same_trace(live, offline)
    values = [e.progress for e in estimates]
    assert values[-1] > 90 and values[0] == 0
    assert values == sorted(values)  # the oracle's truth rises on this episode
    # live values are the trace's values (the plan never grew)
    assert values == pytest.approx(live.progress(), abs=1e-9)
    # the last subtask ends on the last frame; the parent's "Task complete" turn would
    # come with a next frame (offline: the video ends first, as here)
    assert live.tree.children[-1].outcome == "complete" and not stream.complete
    assert [e.subtask_path for e in estimates][-1] == ["place the can in the bin"]


async def test_work_per_frame_and_frames_held_are_bounded(make_episode, scripted, chatty):
    ep = make_episode(40)
    vlm = scripted(chatty)
    stream = RoverStream(ep.task, vlm, episode_id=ep.id)
    held = []
    for frame in ep.frames():
        before = len(vlm.prompts)
        est = await stream.push(frame)
        steps = [p for p in vlm.prompts[before:] if p.meta.kind == "rover.step"]
        fresh = [p for p in steps if not p.meta.extra.get("reminder")]
        assert len(fresh) <= 1  # one step call per frame (plus its re-ask, if any)
        parents = len(vlm.prompts[before:]) - len(steps)
        assert parents <= 2  # parent turns only when a subtask ends (two nested here)
        assert est.calls == len(vlm.prompts) - before
        held.append(stream.frames_held())
    # pixels kept: each open line's initial scene, window and last frame — not the video
    assert max(held) <= 6
    trace = await stream.trace()
    assert trace.num_frames == 40 and trace.frame_indices == list(range(40))


async def test_frames_after_completion_cost_nothing(make_episode, scripted, chatty):
    ep = make_episode(12)
    stream = RoverStream(TASK, scripted(chatty))
    est = None
    for frame in ep.frames():
        est = await stream.push(frame)
        if est.complete:
            break
    assert est is not None and est.complete
    extra = await stream.push(ep.frames()[-1])
    assert extra.calls == 0 and extra.complete and extra.progress == est.progress


async def test_bad_input_is_refused(make_episode):
    ep = make_episode(4)
    with pytest.raises(InputError, match="ground truth"):
        RoverStream(TASK, load_vlm("oracle"))
    with pytest.raises(InputError, match="ROVER"):
        RoverStream(TASK, load_vlm("oracle"), bind=ep, method="gvl")
    stream = RoverStream(TASK, load_vlm("oracle"), bind=ep)
    with pytest.raises(InputError, match="uint8"):
        await stream.push(ep.frames()[0].astype(float))
    await stream.push(ep.frames()[0], index=5)
    with pytest.raises(InputError, match="increase"):
        await stream.push(ep.frames()[1], index=5)
    with pytest.raises(InputError, match="no frame"):
        await RoverStream(TASK, load_vlm("oracle"), bind=ep).trace()
    await stream.trace()
    with pytest.raises(InputError, match="ended"):
        await stream.push(ep.frames()[1])


async def test_stream_replays_rover_reason_prompt_for_prompt(
    tmp_path, make_episode, scripted, chatty
):
    """`rover reason` on a frame folder, then the same frames pushed through a replay of
    its cassette: replay matches prompts by fingerprint, so every prompt must be identical."""
    import asyncio

    from PIL import Image
    from typer.testing import CliRunner

    from rover.cli import app
    from rover.io.source import load_episode
    from rover.vlm.cassette import CassetteWriter, RecordingVLM

    folder = tmp_path / "frames"
    folder.mkdir()
    for t, arr in enumerate(make_episode(14, size=48).views["left"]):
        Image.fromarray(arr).save(folder / f"frame_{t:03d}.png")
    ep = load_episode(str(folder), size=256, task=TASK)
    cassette = tmp_path / "c.jsonl"
    await get_method("rover").run(ep, RecordingVLM(scripted(chatty), CassetteWriter(cassette)))
    out = tmp_path / "reason.json"
    args = ["reason", str(folder), "--task", TASK, "--backend", f"replay:{cassette}"]
    res = await asyncio.to_thread(CliRunner().invoke, app, [*args, "--out", str(out)])
    assert res.exit_code == 0, res.output
    offline = Trace.load(out)
    live, _, _ = await stream_video(ep, load_vlm(f"replay:{cassette}"))
    assert_same_trace(live, offline)


async def test_unrecorded_stream_keeps_memory_bounded_and_same_estimates(
    make_episode, scripted, chatty
):
    """record=False: the same estimates and totals, with nothing kept per frame."""
    ep = make_episode(40)
    full, lean = (
        RoverStream(TASK, scripted(chatty)),
        RoverStream(TASK, scripted(chatty), record=False),
    )
    for frame in ep.frames():
        a, b = await full.push(frame), await lean.push(frame)
        assert (a.progress, a.subtask_path, a.description, a.calls) == (
            b.progress,
            b.subtask_path,
            b.description,
            b.calls,
        )
        s = lean._session
        assert len(s.trace.frames.items) <= 6 and len(s.trace.frame_indices.items) <= 6
        assert list(s.trace.calls) == []  # counted, not kept
    kept, summary = await full.trace(), await lean.trace()
    assert summary.frames == [] and summary.calls == [] and summary.num_frames == 40
    assert summary.totals.model_dump(exclude={"latency_s"}) == kept.totals.model_dump(
        exclude={"latency_s"}
    )
    assert summary.tree == kept.tree
    assert summary.params["record"] is False
    assert Trace.model_validate_json(summary.model_dump_json()) == summary  # saves and loads
