"""How long does sampling 30 frames from a 1,000-frame episode take? Target: <= 0.5 s.

Writes 256 px test videos -- H.264 as rover writes datasets (`write_video`, a keyframe
every 15 frames), AV1 as LeRobot encodes it (GOP 2), and, for reference, both codecs
with their encoder's default GOP (x264: 250, SVT-AV1: ~160) -- then times
`rover.io.seek.decode_frames` (index by demuxing, then keyframe seeking) against a full
sequential decode, and checks both give identical pixels. Prints a table.

The target applies to the first two rows. With a default GOP there are only a handful
of keyframes, so any reader must decode nearly every frame up to the last one sampled;
those rows show what seeking cannot save.

    python benchmarks/decode_speed.py [--frames 1000] [--sample 30] [--size 256]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from fractions import Fraction
from pathlib import Path

import av
import numpy as np

from rover.episode import even_positions
from rover.io.seek import decode_frames, index_video
from rover.io.video import read_video, write_video

TARGET_S = 0.5


def synthetic_frames(n: int, size: int) -> np.ndarray:
    """A textured scene with a moving block and mild noise, so the codec has real work."""
    rng = np.random.default_rng(0)
    yy, xx = np.mgrid[0:size, 0:size]
    base = np.stack([(xx * 255 // size), (yy * 255 // size), ((xx + yy) * 127 // size)], -1)
    base = base.astype(np.uint8)
    out = np.empty((n, size, size, 3), dtype=np.uint8)
    block = size // 6
    for t in range(n):
        frame = base.copy()
        x = int((size - block) * (0.5 + 0.5 * np.sin(t / 40)))
        y = int((size - block) * t / max(n - 1, 1))
        frame[y : y + block, x : x + block] = (240, 200, 30)
        noise = rng.integers(0, 12, size=(size, size, 1), dtype=np.uint8)
        out[t] = frame + noise
    return out


def encode(path: Path, frames: np.ndarray, codec: str, gop: int | None, fps: int = 30) -> None:
    with av.open(str(path), "w", format="mp4") as container:
        stream = container.add_stream(codec, rate=Fraction(fps))
        stream.width, stream.height, stream.pix_fmt = frames.shape[2], frames.shape[1], "yuv420p"
        if gop:
            stream.codec_context.gop_size = gop
        if codec == "libsvtav1":
            stream.options = {"preset": "10", "crf": "30"}
        else:
            stream.options = {"crf": "23", "preset": "veryfast"}
        for arr in frames:
            container.mux(stream.encode(av.VideoFrame.from_ndarray(arr, format="rgb24")))
        container.mux(stream.encode())


def best_of(fn, repeats: int = 3) -> tuple[float, object]:
    best, result = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=1000)
    parser.add_argument("--sample", type=int, default=30)
    parser.add_argument("--size", type=int, default=256)
    args = parser.parse_args()

    frames = synthetic_frames(args.frames, args.size)
    wanted = even_positions(args.frames, args.sample)
    # (label, codec, gop, held to the target)
    cases = [
        ("H.264 (rover write_video, GOP 15)", "rover", 15, True),
        ("AV1 (LeRobot-style, GOP 2)", "libsvtav1", 2, True),
        ("H.264 (x264 default GOP)", "libx264", None, False),
        ("AV1 (SVT-AV1 default GOP)", "libsvtav1", None, False),
    ]
    rows = []
    av.logging.set_level(av.logging.ERROR)
    with tempfile.TemporaryDirectory() as tmp:
        for label, codec, gop, held in cases:
            path = Path(tmp) / f"{codec}_{gop}.mp4"
            if codec == "rover":
                write_video(path, frames, fps=30)
            else:
                encode(path, frames, codec, gop)
            keyframes = len(index_video(path).keyframe_pts)
            sampled_s, sampled = best_of(lambda p=path: decode_frames(p, wanted), repeats=5)
            full_s, full = best_of(lambda p=path: read_video(p), repeats=1)
            exact = bool(np.array_equal(sampled, full[wanted]))
            rows.append(
                (label, args.frames, keyframes, len(wanted), sampled_s, full_s, exact, held)
            )

    header = (
        "format",
        "frames in video",
        "keyframes",
        "frames sampled",
        "seconds",
        "full decode s",
        "exact",
        "target",
    )
    print(" | ".join(header))
    print(" | ".join("---" for _ in header))
    for label, n, kf, k, s, f, exact, held in rows:
        target = ("met" if s <= TARGET_S else "MISSED") if held else "(reference)"
        same = "yes" if exact else "NO"
        print(f"{label} | {n} | {kf} | {k} | {s:.3f} | {f:.3f} | {same} | {target}")
    ok = all(r[6] for r in rows) and all(r[4] <= TARGET_S for r in rows if r[7])
    print(f"\ntarget: sampling <= {TARGET_S} s and frame-exact: {'met' if ok else 'NOT met'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
