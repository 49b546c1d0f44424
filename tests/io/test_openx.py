"""The App. L benchmark helpers: dataset discovery and reproducible episode draws."""

from __future__ import annotations

import pytest

from rover.errors import InputError
from rover.io.openx import OPENX_DATASETS, PAPER_VOC, benchmark_episodes, discover_openx
from rover.io.source import load_episode, with_frame_number_truth


def test_paper_tables_cover_fifty_datasets():
    assert len(OPENX_DATASETS) == 50
    assert PAPER_VOC["bridge"] == ((0.457, 0.717), (0.661, 0.799))
    assert PAPER_VOC["droid"][1] is None  # not in the GPT-4o table


def test_discover_and_sample(tmp_path, make_rlds, make_lerobot_v2):
    make_rlds(tmp_path / "bridge" / "0.1.0", shards=((5, 5, 5), (5,)), image_keys=("image",))
    make_rlds(tmp_path / "toto", shards=((4, 4),), image_keys=("image",))
    make_lerobot_v2(tmp_path / "viola", lengths=(6, 6, 6))
    (tmp_path / "not_openx").mkdir()
    specs = discover_openx(tmp_path)
    assert specs == {
        "toto": f"rlds:{tmp_path / 'toto'}",
        "bridge": f"rlds:{tmp_path / 'bridge'}",
        "viola": f"lerobot:{tmp_path / 'viola'}",
    }
    picks = benchmark_episodes(specs, per_dataset=2, seed=0)
    assert picks == benchmark_episodes(specs, per_dataset=2, seed=0)
    assert [p.dataset for p in picks].count("bridge") == 2
    assert len(picks) == 6
    first = picks[0]
    ep = with_frame_number_truth(load_episode(f"{first.spec}?episode={first.episode_id}"))
    assert ep.truth.progress[0] == 0.0 and ep.truth.progress[-1] == 1.0
    with pytest.raises(InputError, match="no such directory"):
        discover_openx(tmp_path / "missing")
