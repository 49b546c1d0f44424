"""Cassettes: record through the loopback openai backend, replay with zero requests."""

from __future__ import annotations

import asyncio
import json

import pytest

from rover.errors import BackendError, InputError
from rover.vlm import load_vlm


def test_record_then_replay_round_trip(openai_server, fast_config, make_prompt, tmp_path):
    cassette = tmp_path / "run" / "cassette.jsonl"
    openai_server.answer = lambda body: f"answer #{len(openai_server.requests)}"
    prompts = [make_prompt(first_frame=i, kind="rover.step") for i in range(3)]
    recorder = load_vlm(
        f"openai:m@{openai_server.base_url}", fast_config.model_copy(update={"record": cassette})
    )
    assert recorder.backend == "openai" and recorder.bind(object()).backend == "openai"

    async def ask(vlm):
        return [await vlm.complete(p) for p in prompts]

    recorded = asyncio.run(ask(recorder))
    assert openai_server.count == 3
    lines = [json.loads(x) for x in cassette.read_text().splitlines()]
    assert [x["kind"] for x in lines] == ["rover.step"] * 3
    assert [x["frames"] for x in lines] == [[0], [1], [2]]
    assert "/9j/" not in cassette.read_text()  # no base64 JPEG: images are never stored

    replay = load_vlm(f"replay:{cassette}")
    replayed = asyncio.run(ask(replay))
    assert openai_server.count == 3  # nothing sent
    assert [c.text for c in replayed] == [c.text for c in recorded]
    assert [c.usage for c in replayed] == [c.usage for c in recorded]
    assert {c.backend for c in replayed} == {"replay"} and replayed[0].model == "m"


def test_missing_prompt_names_kind_and_frames(openai_server, fast_config, make_prompt, tmp_path):
    cassette = tmp_path / "c.jsonl"
    config = fast_config.model_copy(update={"record": cassette})
    asyncio.run(load_vlm(f"openai:m@{openai_server.base_url}", config).complete(make_prompt()))
    replay = load_vlm(f"replay:{cassette}")
    with pytest.raises(BackendError, match=r"kind=gvl.batch frames=\[5, 6\]"):
        asyncio.run(replay.complete(make_prompt(kind="gvl.batch", first_frame=5, n_images=2)))


def test_repeated_prompts_replay_in_recorded_order(
    openai_server, fast_config, make_prompt, tmp_path
):
    cassette = tmp_path / "c.jsonl"
    config = fast_config.model_copy(update={"record": cassette, "no_cache": True})
    answers = iter(["first", "second"])
    openai_server.answer = lambda body: next(answers)
    vlm = load_vlm(f"openai:m@{openai_server.base_url}", config)
    prompt = make_prompt()
    asyncio.run(vlm.complete(prompt))
    asyncio.run(vlm.complete(prompt))
    replay = load_vlm(f"replay:{cassette}")
    texts = [asyncio.run(replay.complete(prompt)).text for _ in range(3)]
    assert texts == ["first", "second", "second"]


def test_truncated_last_line_is_tolerated_but_corruption_is_not(tmp_path, make_prompt):
    entry = {"key": "k", "prompt": "p", "text": "t", "model": "m", "usage": {}}
    cassette = tmp_path / "c.jsonl"
    cassette.write_text(json.dumps(entry) + "\n" + json.dumps(entry)[:20])
    load_vlm(f"replay:{cassette}")  # an interrupted recording still replays
    cassette.write_text("{broken\n" + json.dumps(entry) + "\n")
    with pytest.raises(InputError, match="line 1"):
        load_vlm(f"replay:{cassette}")
    with pytest.raises(InputError, match="no cassette"):
        load_vlm(f"replay:{tmp_path / 'nope.jsonl'}")


def test_replay_never_touches_the_cache(tmp_path, openai_server, fast_config, make_prompt):
    cassette = tmp_path / "c.jsonl"
    config = fast_config.model_copy(update={"record": cassette, "no_cache": True})
    asyncio.run(load_vlm(f"openai:m@{openai_server.base_url}", config).complete(make_prompt()))
    replay_config = fast_config.model_copy(update={"cache_path": tmp_path / "replay.sqlite"})
    completion = asyncio.run(load_vlm(f"replay:{cassette}", replay_config).complete(make_prompt()))
    assert not completion.cached
    assert not (tmp_path / "replay.sqlite").exists()
