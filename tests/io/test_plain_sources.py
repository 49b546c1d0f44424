"""Plain sources: a video file, a folder of numbered frames, a rover dataset directory."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rover.episode import Episode
from rover.errors import InputError
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode
from rover.io.source import (
    load_episode,
    open_source,
    parse_spec,
    sample_episode_ids,
    with_frame_number_truth,
)

from .conftest import frames_for, write_mp4


def test_video_file_samples_evenly_and_resizes(tmp_path):
    path = write_mp4(tmp_path / "push_block.mp4", frames_for(40, 96, width=128), fps=15)
    ep = load_episode(path, frames=5, size=64)
    assert ep.id == "push_block" and ep.task == "" and ep.fps == 15
    assert ep.frame_indices == [0, 10, 20, 29, 39]
    assert ep.frames().shape == (5, 48, 64, 3)  # long side 64, aspect kept
    assert ep.truth is None and ep.extra["total_frames"] == 40
    big = load_episode(path, frames=2, size=1024, task="push the block")
    assert big.frames().shape == (2, 96, 128, 3)  # never upscaled
    assert big.task == "push the block"
    truth = with_frame_number_truth(ep).truth
    assert truth.progress_source == "frame_number"
    assert truth.progress == pytest.approx([i / 39 for i in (0, 10, 20, 29, 39)])


def test_frame_folder_sorted_by_number_with_gaps(tmp_path):
    folder = tmp_path / "attempt_3"
    folder.mkdir()
    frames = frames_for(13, 32)
    for i in (2, 6, 12):
        Image.fromarray(frames[i]).save(folder / f"frame_{i}.png")
    Image.fromarray(frames[9]).save(folder / "frame_9.jpg", quality=95)
    (folder / "notes.txt").write_text("ignored")
    ep = load_episode(folder, size=None)
    assert ep.id == "attempt_3" and ep.frame_indices == [2, 6, 9, 12]
    assert np.array_equal(ep.frames()[[0, 1, 3]], frames[[2, 6, 12]])
    sub = load_episode(f"frames:{folder}", frames=2)
    assert sub.frame_indices == [2, 12]
    # numbering starts at 2: progress runs over 2..12
    assert with_frame_number_truth(ep).truth.progress == pytest.approx([0, 0.4, 0.7, 1])


def test_frame_folder_errors(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputError, match="no frames found"):
        load_episode(empty)
    dup = tmp_path / "dup"
    dup.mkdir()
    Image.fromarray(frames_for(1, 16)[0]).save(dup / "a_1.png")
    Image.fromarray(frames_for(1, 16)[0]).save(dup / "a_01.png")  # same camera, same number
    with pytest.raises(InputError, match="frame number 1 also used"):
        load_episode(dup)
    sizes = tmp_path / "sizes"
    sizes.mkdir()
    Image.fromarray(frames_for(1, 16)[0]).save(sizes / "f0.png")
    Image.fromarray(frames_for(1, 24)[0]).save(sizes / "f1.png")
    with pytest.raises(InputError, match=r"f1\.png: frame size 24x24 differs"):
        load_episode(sizes)
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "f0.png").write_bytes(b"not a png")
    with pytest.raises(InputError, match=r"f0\.png: unreadable image"):
        load_episode(bad)


def test_dataset_dir_and_single_episode_folder(tmp_path, make_episode):
    write_dataset_info(tmp_path, DatasetInfo(name="t", views=["left"]))
    for i in range(3):
        write_episode(tmp_path, make_episode(n=10, size=32, episode_id=f"ep{i}"))
    reader = open_source(tmp_path)
    assert reader.kind == "dataset" and reader.episode_ids() == ["ep0", "ep1", "ep2"]
    ep = reader.read("ep1", frames=4)
    assert ep.frame_indices == [0, 3, 6, 9] and ep.truth.progress[-1] == 1.0
    assert ep.frames().shape == (4, 32, 32, 3)
    one = load_episode(tmp_path / "episodes" / "ep2", frames=3, view="left")
    assert one.id == "ep2" and one.view == "left" and one.num_frames == 3
    with pytest.raises(InputError, match="holds 3 episodes"):
        load_episode(tmp_path)
    with pytest.raises(InputError, match="no view 'top'"):
        load_episode(tmp_path / "episodes" / "ep2", view="top")
    assert load_episode(f"dataset:{tmp_path}?episode=ep0").id == "ep0"


def test_iteration_uses_reader_defaults(tmp_path, make_episode):
    write_dataset_info(tmp_path, DatasetInfo(name="t", views=["left"]))
    for i in range(2):
        write_episode(tmp_path, make_episode(n=8, size=32, episode_id=f"e{i}"))
    episodes = list(open_source(tmp_path, frames=3, size=16))
    assert [e.id for e in episodes] == ["e0", "e1"]
    assert all(isinstance(e, Episode) and e.frames().shape == (3, 16, 16, 3) for e in episodes)


def test_sample_episode_ids_is_reproducible(tmp_path, make_episode):
    write_dataset_info(tmp_path, DatasetInfo(name="t", views=["left"]))
    for i in range(6):
        write_episode(tmp_path, make_episode(n=3, size=16, episode_id=f"e{i}"))
    reader = open_source(tmp_path)
    a = sample_episode_ids(reader, 3, seed=0)
    assert a == sample_episode_ids(reader, 3, seed=0)
    assert len(set(a)) == 3 and a == sorted(a)  # source order
    assert any(sample_episode_ids(reader, 3, seed=s) != a for s in range(1, 6))
    assert sample_episode_ids(reader, 10, seed=0) == reader.episode_ids()


def test_spec_parsing_and_unknown_prefix(tmp_path):
    assert parse_spec("lerobot:/data/x?camera=top&episode=episode_000001") == (
        "lerobot",
        tmp_path.__class__("/data/x"),
        {"camera": "top", "episode": "episode_000001"},
    )
    with pytest.raises(InputError, match="unknown source prefix 'youtube:'.*lerobot:"):
        open_source("youtube:abc")
    with pytest.raises(InputError, match="no such file"):
        open_source(tmp_path / "missing.mp4")
    (tmp_path / "clip.txt").write_text("x")
    with pytest.raises(InputError, match="unsupported file type '.txt'"):
        open_source(tmp_path / "clip.txt")
    with pytest.raises(InputError, match="unknown option 'bogus'"):
        open_source(f"lerobot:{tmp_path}?bogus=1")
