"""Episodes from every real-data format go through a reasoning method end to end."""

from __future__ import annotations

import pytest

from rover.episode import Episode
from rover.io.source import load_episode, open_source, with_frame_number_truth
from rover.vlm.types import Completion, Prompt, SamplingParams, Usage

registry = pytest.importorskip("rover.methods.registry")


class CountingVLM:
    """A tiny fake VLM: says progress = shown frame's original index / last index."""

    backend = "fake"
    model = "counting"

    def __init__(self) -> None:
        self.last_index = 1
        self.calls = 0

    def bind(self, episode: Episode) -> CountingVLM:
        self.last_index = max(episode.frame_indices[-1], 1)
        return self

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        self.calls += 1
        idx = prompt.meta.frame_indices[-1]
        pct = round(100 * idx / self.last_index)
        return Completion(
            text=f"Frame description: The robot arm moves.\nTask completion percentage: {pct}%",
            usage=Usage(prompt_tokens=10, completion_tokens=5),
        )


def _sources(tmp_path, make_lerobot_v2, make_lerobot_v3, make_rlds, make_robomimic):
    v2 = make_lerobot_v2(tmp_path / "v2", lengths=(10,))
    v3 = make_lerobot_v3(tmp_path / "v3", lengths=(6, 10), codec="libsvtav1")
    rlds = make_rlds(tmp_path / "rlds", shards=((10,),), image_keys=("image",))
    h5 = make_robomimic(tmp_path / "demo.hdf5", lengths=(10,))
    return [
        f"lerobot:{v2}",
        f"lerobot:{v3}?episode=episode_000001",
        f"rlds:{rlds}",
        f"hdf5:{h5}",
    ]


async def test_temporal_concat_runs_on_every_format(
    tmp_path, make_lerobot_v2, make_lerobot_v3, make_rlds, make_robomimic
):
    method = registry.get_method("temporal-concat")
    for spec in _sources(tmp_path, make_lerobot_v2, make_lerobot_v3, make_rlds, make_robomimic):
        episode = with_frame_number_truth(load_episode(spec, frames=5))
        assert episode.task, spec
        vlm = CountingVLM()
        trace = await method.run(episode, vlm)
        assert vlm.calls == 4, spec
        assert [f.index for f in trace.frames] == episode.frame_indices
        got = [f.progress for f in trace.frames]
        want = [100 * p for p in episode.truth.progress]
        assert got == pytest.approx(want, abs=1.0), spec


def test_every_reader_iterates_episodes(
    tmp_path, make_lerobot_v2, make_lerobot_v3, make_rlds, make_robomimic
):
    for spec in _sources(tmp_path, make_lerobot_v2, make_lerobot_v3, make_rlds, make_robomimic):
        episodes = list(open_source(spec, frames=3, size=32))
        assert episodes and all(e.num_frames == 3 for e in episodes)
        assert all(max(e.frames().shape[1:3]) <= 32 for e in episodes)
