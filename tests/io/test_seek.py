"""Keyframe seeking returns exactly the frames a full decode would, for every codec."""

from __future__ import annotations

import av
import numpy as np
import pytest

from rover.errors import InputError
from rover.io.seek import decode_frames, index_video
from rover.io.source import load_episode
from rover.io.video import read_video

from .conftest import frames_for, write_mp4


@pytest.mark.parametrize(("codec", "gop"), [("libx264", 12), ("libx264", None), ("libsvtav1", 16)])
def test_seeking_is_frame_exact(tmp_path, codec, gop):
    path = write_mp4(tmp_path / f"{codec}.mp4", frames_for(90, 64), fps=30, codec=codec, gop=gop)
    index = index_video(path)
    assert index.num_frames == 90
    if gop:
        assert len(index.keyframe_pts) > 1
    full = read_video(path)
    for wanted in ([0, 1, 2], [5, 40, 41, 89], [13, 30, 47, 64, 81], [89], list(range(0, 90, 7))):
        assert np.array_equal(decode_frames(path, wanted, index), full[wanted]), wanted


def test_read_video_positions_use_seeking_and_check_range(tmp_path):
    path = write_mp4(tmp_path / "v.mp4", frames_for(20, 32), gop=5)
    full = read_video(path)
    assert np.array_equal(read_video(path, [19, 3, 3]), full[[3, 19]])  # sorted, deduplicated
    with pytest.raises(InputError, match="asked for frame 25 but the video has 20 frames"):
        read_video(path, [0, 25])


def test_webm_vp9_container_reads(tmp_path):
    if "libvpx-vp9" not in av.codecs_available:
        pytest.skip("no VP9 encoder in this PyAV build")
    path = tmp_path / "clip.webm"
    frames = frames_for(10, 32)
    with av.open(str(path), "w", format="webm") as c:
        s = c.add_stream("libvpx-vp9", rate=10)
        s.width = s.height = 32
        s.pix_fmt = "yuv420p"
        for f in frames:
            c.mux(s.encode(av.VideoFrame.from_ndarray(f, format="rgb24")))
        c.mux(s.encode())
    ep = load_episode(path, frames=4)
    assert ep.frame_indices == [0, 3, 6, 9] and ep.frames().shape == (4, 32, 32, 3)


def test_truncated_and_garbage_videos_are_one_line_errors(tmp_path):
    path = write_mp4(tmp_path / "cut.mp4", frames_for(30, 64))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 3])
    with pytest.raises(InputError) as err:
        load_episode(path, frames=4)
    assert str(path) in str(err.value) and "\n" not in str(err.value)
    # moov atom first ("faststart"), media data cut: the header knows how many frames
    fast = tmp_path / "fast.mp4"
    with av.open(str(fast), "w", format="mp4", options={"movflags": "faststart"}) as c:
        s = c.add_stream("libx264", rate=10)
        s.width = s.height = 64
        s.pix_fmt = "yuv420p"
        for f in frames_for(60, 64):
            c.mux(s.encode(av.VideoFrame.from_ndarray(f, format="rgb24")))
        c.mux(s.encode())
    fast.write_bytes(fast.read_bytes()[: fast.stat().st_size // 2])
    with pytest.raises(
        InputError, match=r"fast\.mp4: truncated or damaged video \(header lists 60"
    ):
        load_episode(fast, frames=5)
    junk = tmp_path / "junk.mp4"
    junk.write_bytes(b"\0" * 100)
    with pytest.raises(InputError, match=r"junk\.mp4: (corrupt|cannot read)"):
        load_episode(junk)
