"""OpenX RLDS TFRecords written by the factory (real framing, CRCs and protobufs)."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

from rover.errors import InputError
from rover.io.source import load_episode, open_source
from rover.io.tfrecord import crc32c, decode_example

from .conftest import encode_example, frames_for, write_tfrecord


def test_crc32c_known_vector():
    # the standard check value of CRC-32C
    assert crc32c(b"123456789") == 0xE3069283


def test_example_decoding_round_trips_every_list_kind():
    raw = encode_example({"a": [b"x", b"yz"], "f": [1.5, -2.0], "i": [3, -1, 1 << 40]})
    features, lists = decode_example(raw)
    assert lists == {}
    assert features["a"].kind == "bytes_list" and features["a"].value == [b"x", b"yz"]
    assert features["f"].value.tolist() == [1.5, -2.0]
    assert features["i"].value.tolist() == [3, -1, 1 << 40]


def test_rlds_folder_lists_shards_and_reads_steps(tmp_path, make_rlds):
    root = make_rlds(tmp_path / "toy" / "0.1.0", shards=((10, 8), (6,)))
    reader = open_source(f"rlds:{tmp_path / 'toy'}")  # finds the single version folder
    assert reader.episode_ids() == ["train-00000-0000", "train-00000-0001", "train-00001-0000"]
    ep = reader.read("train-00000-0001", frames=3, size=None)
    assert ep.task == "close the drawer"
    assert ep.frame_indices == [0, 4, 7]
    assert ep.view == "image" and ep.view_names == ["image", "wrist_image"]
    assert ep.extra["dataset"] == "toy_dataset" and ep.extra["total_frames"] == 8
    diff = np.abs(ep.frames().astype(int) - frames_for(8, 64, seed=10)[[0, 4, 7]]).mean()
    assert diff < 8  # JPEG
    wrist = load_episode(f"rlds:{root}?camera=wrist_image&episode=train-00001-0000&verify=1")
    assert wrist.view == "wrist_image" and wrist.num_frames == 6


def test_png_steps_are_exact_and_schema_is_optional(tmp_path, make_rlds):
    root = make_rlds(tmp_path / "png", shards=((5,),), fmt="png", image_keys=("image",))
    (root / "features.json").unlink()
    ep = load_episode(f"rlds:{root}", size=None)
    assert np.array_equal(ep.frames(), frames_for(5, 64, seed=0))
    assert ep.task == "put the spoon in the pot"


def test_wrong_feature_type_names_file_and_field(tmp_path, make_rlds):
    root = make_rlds(tmp_path / "bad", shards=((4,),), image_keys=("image",))
    shard = next(root.glob("*.tfrecord*"))
    write_tfrecord(shard, [encode_example({"steps/observation/image": [0.5] * 4})])
    with pytest.raises(InputError) as err:
        load_episode(f"rlds:{root}")
    msg = str(err.value)
    assert shard.name in msg and "'steps/observation/image'" in msg and "float_list" in msg
    assert "\n" not in msg


def test_truncated_and_corrupt_shards(tmp_path, make_rlds):
    root = make_rlds(tmp_path / "cut", shards=((4,),), image_keys=("image",))
    shard = next(root.glob("*.tfrecord*"))
    data = shard.read_bytes()
    shard.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match=rf"{shard.name}: record 0 truncated"):
        open_source(f"rlds:{root}").episode_ids()
    shard.write_bytes(struct.pack("<Q", 5) + b"\0\0\0\0" + b"hello\0\0\0\0")
    with pytest.raises(InputError, match="bad TFRecord length checksum"):
        open_source(f"rlds:{root}").episode_ids()
    good = encode_example({"steps/observation/image": [b"x"]})
    write_tfrecord(shard, [good])
    shard.write_bytes(shard.read_bytes()[:-2] + b"\0\0")  # damage the data CRC
    with pytest.raises(InputError, match="data checksum"):
        load_episode(f"rlds:{root}?verify=1")


def test_missing_shards_and_bad_features_json(tmp_path, make_rlds):
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "features.json").write_text("{}")
    with pytest.raises(InputError, match="no TFRecord shards"):
        open_source(f"rlds:{empty}")
    root = make_rlds(tmp_path / "bad", shards=((3,),), image_keys=("image",))
    (root / "features.json").write_text("{not json")
    with pytest.raises(InputError, match=r"features\.json"):
        open_source(f"rlds:{root}")
    (root / "features.json").write_text(json.dumps({"featuresDict": {"features": {}}}))
    with pytest.raises(InputError, match="no image feature"):
        load_episode(f"rlds:{root}")


def test_sequence_example_records(tmp_path):
    from .conftest import _field, encode_feature, encode_image

    frames = frames_for(4, 32)
    # SequenceExample: context Features (1) + FeatureLists (2) of per-step Features
    context = _field(
        1, _field(1, b"steps/language_instruction") + _field(2, encode_feature(["wipe the table"]))
    )
    step_list = b"".join(_field(1, encode_feature([encode_image(f)])) for f in frames)
    lists = _field(1, _field(1, b"steps/observation/image") + _field(2, step_list))
    write_tfrecord(
        tmp_path / "seq-train.tfrecord-00000-of-00001", [_field(1, context) + _field(2, lists)]
    )
    ep = load_episode(f"rlds:{tmp_path}", size=None)
    assert ep.task == "wipe the table"
    assert np.array_equal(ep.frames(), frames)


def test_mixed_frame_sizes_and_depth_camera_default(tmp_path):
    from .conftest import encode_image

    small, big = frames_for(1, 32)[0], frames_for(1, 48)[0]
    feats = {
        "steps/observation/depth_image": [encode_image(small)] * 2,
        "steps/observation/top_rgb": [encode_image(small), encode_image(big)],
        "steps/language_instruction": [b"push the button"] * 2,
    }
    write_tfrecord(tmp_path / "mix-train.tfrecord-00000-of-00001", [encode_example(feats)])
    reader = open_source(f"rlds:{tmp_path}")
    with pytest.raises(InputError, match=r"'steps/observation/top_rgb'.*frame 1 is 48x48"):
        reader.read(reader.episode_ids()[0])  # the colour camera is the default, not depth
    depth = load_episode(f"rlds:{tmp_path}?camera=depth_image")
    assert depth.view == "depth_image" and depth.task == "push the button"
