"""Frame-exact sampling of a few frames from a long video by seeking to keyframes.

Decoding every frame of a 1,000-frame episode to keep 30 wastes most of the work. We
first demux the stream (reads packets, decodes nothing) to learn each frame's
presentation timestamp and where the keyframes are; then, for each wanted frame, we
either keep decoding forward (when no keyframe lies between us and the target) or seek
to the last keyframe at or before it. Frames are matched by timestamp, so the result is
identical to a full decode — tests check exactly that.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import av
import numpy as np

from rover.errors import InputError


@dataclass(frozen=True)
class VideoIndex:
    """Presentation timestamps of every frame (in display order) and of the keyframes."""

    path: Path
    pts: np.ndarray  # int64, sorted: pts[i] is frame i
    keyframe_pts: np.ndarray  # int64, sorted
    time_base: float
    fps: float
    width: int
    height: int

    @property
    def num_frames(self) -> int:
        return len(self.pts)

    def times(self) -> np.ndarray:
        """Presentation time of each frame in seconds."""
        return self.pts.astype(np.float64) * self.time_base


def index_video(path: Path) -> VideoIndex:
    """Demux (without decoding) to find every frame's timestamp and the keyframes."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: no such video file")
    pts: list[int] = []
    keys: list[int] = []
    try:
        with av.open(str(path)) as container:
            if not container.streams.video:
                raise InputError(f"{path}: no video stream")
            stream = container.streams.video[0]
            for packet in container.demux(stream):
                if packet.size == 0 or packet.pts is None:
                    continue
                pts.append(int(packet.pts))
                if packet.is_keyframe:
                    keys.append(int(packet.pts))
            declared = int(stream.frames or 0)
            fps = float(stream.average_rate or stream.guessed_rate or 30.0)
            time_base = float(stream.time_base) if stream.time_base else 1.0 / fps
            width, height = stream.codec_context.width, stream.codec_context.height
    except av.error.FFmpegError as exc:
        raise InputError(f"{path}: corrupt or unreadable video ({exc})") from exc
    if not pts:
        raise InputError(f"{path}: video has no frames")
    if declared and len(pts) < declared:
        raise InputError(
            f"{path}: truncated or damaged video (header lists {declared} frames, "
            f"{len(pts)} readable)"
        )
    return VideoIndex(
        path=path,
        pts=np.unique(np.asarray(pts, dtype=np.int64)),
        keyframe_pts=np.unique(np.asarray(keys or pts[:1], dtype=np.int64)),
        time_base=time_base,
        fps=fps,
        width=width,
        height=height,
    )


def decode_frames(path: Path, indices: list[int], index: VideoIndex | None = None) -> np.ndarray:
    """The frames at the given display-order indices, (len, H, W, 3) uint8 RGB.

    Indices must be increasing. Falls back to a plain sequential decode for streams
    whose packets carry no timestamps.
    """
    path = Path(path)
    index = index or index_video(path)
    if not indices:
        raise ValueError("no frame indices given")
    if any(b <= a for a, b in zip(indices, indices[1:], strict=False)):
        raise ValueError("frame indices must be strictly increasing")
    if indices[0] < 0 or indices[-1] >= index.num_frames:
        raise InputError(
            f"{path}: asked for frame {indices[-1]} but the video has {index.num_frames} frames"
        )
    targets = [int(index.pts[i]) for i in indices]
    try:
        out = _seek_and_decode(path, index, targets)
    except av.error.FFmpegError as exc:
        raise InputError(f"{path}: corrupt or unreadable video ({exc})") from exc
    if out is None:
        raise InputError(f"{path}: could not decode frames {indices[:3]}... (damaged stream?)")
    return np.stack(out)


def _seek_and_decode(path: Path, index: VideoIndex, targets: list[int]) -> list[np.ndarray] | None:
    out: list[np.ndarray] = []
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        stream.thread_type = "AUTO"
        decoder = None
        last_pts: int | None = None  # pts of the last frame the decoder produced
        for target in targets:
            key = _keyframe_at_or_before(index, target)
            must_seek = decoder is None or last_pts is None or last_pts >= target or key > last_pts
            if must_seek:
                container.seek(int(key), stream=stream, backward=True, any_frame=False)
                decoder = container.decode(stream)
                last_pts = None
            found = None
            for frame in decoder:
                if frame.pts is None:
                    continue
                last_pts = int(frame.pts)
                if last_pts == target:
                    found = frame
                    break
                if last_pts > target:
                    break
            if found is None:
                return None
            out.append(found.to_ndarray(format="rgb24"))
    return out


def _keyframe_at_or_before(index: VideoIndex, pts: int) -> int:
    k = int(np.searchsorted(index.keyframe_pts, pts, side="right")) - 1
    return int(index.keyframe_pts[max(k, 0)])
