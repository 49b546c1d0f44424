"""Pixel-level helpers shared by every source: resizing and stacking frames."""

from __future__ import annotations

import numpy as np
from PIL import Image

from rover.errors import InputError


def resize_long_side(frames: np.ndarray, size: int) -> np.ndarray:
    """Scale (T, H, W, 3) frames so the long side is `size` px; never upscales."""
    if frames.ndim != 4:
        raise ValueError(f"expected (T, H, W, 3) frames, got shape {frames.shape}")
    t, h, w, _ = frames.shape
    if max(h, w) <= size:
        return frames
    scale = size / max(h, w)
    nw, nh = max(1, round(w * scale)), max(1, round(h * scale))
    out = np.empty((t, nh, nw, 3), dtype=np.uint8)
    for i in range(t):
        out[i] = np.asarray(Image.fromarray(frames[i]).resize((nw, nh), Image.BILINEAR))
    return out


def to_rgb_array(img: Image.Image) -> np.ndarray:
    """A PIL image as a contiguous uint8 (H, W, 3) array."""
    return np.ascontiguousarray(np.asarray(img.convert("RGB"), dtype=np.uint8))


def stack_frames(frames: list[np.ndarray], where: str) -> np.ndarray:
    """Stack decoded frames into (T, H, W, 3), naming the first frame whose size differs."""
    if not frames:
        raise InputError(f"{where}: no frames")
    shape = frames[0].shape
    for i, f in enumerate(frames):
        if f.shape != shape:
            raise InputError(
                f"{where}: frame {i} is {f.shape[1]}x{f.shape[0]}, frame 0 is {shape[1]}x{shape[0]}"
            )
    return np.stack(frames)
