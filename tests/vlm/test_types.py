"""Prompt model: images from PIL/arrays/files, encoded once, fingerprints ignore meta."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from rover.errors import InputError
from rover.vlm import (
    EncodedImage,
    ImageEncoding,
    ImagePart,
    Message,
    Prompt,
    PromptMeta,
    TextPart,
)


def _array(seed=0, h=40, w=60):
    return np.random.default_rng(seed).integers(0, 255, (h, w, 3), dtype=np.uint8)


def test_same_pixels_from_array_pil_or_file_encode_once(tmp_path):
    arr = _array()
    path = tmp_path / "frame.png"
    Image.fromarray(arr).save(path)
    a = EncodedImage.from_any(arr)
    assert EncodedImage.from_any(arr) is a  # memoised: no second encode
    b = EncodedImage.from_any(Image.fromarray(arr))
    c = EncodedImage.from_any(path)
    assert a.sha256 == b.sha256 == c.sha256
    assert (a.width, a.height, a.mime) == (60, 40, "image/jpeg")


def test_encoding_settings_format_quality_and_max_side():
    arr = _array(h=300, w=400)
    png = EncodedImage.from_any(arr, ImageEncoding(format="PNG", max_side=100))
    assert png.mime == "image/png" and (png.width, png.height) == (100, 75)
    assert Image.open(io.BytesIO(png.data)).format == "PNG"
    low = EncodedImage.from_any(arr, ImageEncoding(quality=20))
    high = EncodedImage.from_any(arr, ImageEncoding(quality=95))
    assert len(low.data) < len(high.data) and low.sha256 != high.sha256
    small = EncodedImage.from_any(_array(h=20, w=30), ImageEncoding(max_side=100))
    assert (small.width, small.height) == (30, 20)  # never upscaled


def test_rgba_and_grayscale_inputs_encode_as_jpeg():
    rgba = np.zeros((10, 12, 4), dtype=np.uint8)
    assert EncodedImage.from_any(rgba).mime == "image/jpeg"
    gray = np.zeros((10, 12), dtype=np.uint8)
    assert EncodedImage.from_any(gray).width == 12


def test_bad_inputs_are_clear_errors(tmp_path):
    with pytest.raises(InputError, match="not found"):
        EncodedImage.from_any(tmp_path / "missing.png")
    with pytest.raises(ValueError, match="uint8"):
        EncodedImage.from_any(np.zeros((4, 4, 3), dtype=np.float32))


def _prompt(kind, frames, detail=None):
    return Prompt(
        messages=[
            Message(role="system", content="sys"),
            Message(
                role="user",
                content=[ImagePart.from_image(_array(1), detail=detail), TextPart(text="q")],
            ),
        ],
        meta=PromptMeta(kind=kind, frame_indices=frames),
    )


def test_fingerprint_covers_what_the_provider_sees_not_meta():
    a = _prompt("rover.step", [0])
    assert a.fingerprint() == _prompt("gvl.batch", [7]).fingerprint()
    assert a.fingerprint() != _prompt("rover.step", [0], detail="low").fingerprint()
    assert a.describe() == "kind=rover.step frames=[0]"


def test_prompt_round_trips_through_json():
    a = _prompt("rover.step", [3])
    b = Prompt.model_validate_json(a.model_dump_json())
    assert b.fingerprint() == a.fingerprint()
    assert b.images()[0].image.data == a.images()[0].image.data
