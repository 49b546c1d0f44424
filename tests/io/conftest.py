"""Factories that write small *real* datasets in every format rover reads.

Other engineers may reuse them: each fixture returns a function that writes a dataset
under a given folder and returns its path. Frames come from `frames_for`, so a test can
compare decoded pixels with what was written.
"""

from __future__ import annotations

import io
import json
import struct
from collections.abc import Callable
from fractions import Fraction
from pathlib import Path

import av
import numpy as np
import pytest
from PIL import Image

CAMERA = "observation.images.top"
WRIST = "observation.images.wrist"


def frames_for(n: int, size: int = 64, seed: int = 0, width: int | None = None) -> np.ndarray:
    """n distinct frames: a bright bar moving left to right over a seed-tinted gradient."""
    w = width or size
    ramp_x = np.linspace(0, 120, w, dtype=np.float32)
    ramp_y = np.linspace(0, 120, size, dtype=np.float32)
    base = np.zeros((size, w, 3), dtype=np.uint8)
    base[..., 0] = ramp_x[None, :]
    base[..., 1] = ramp_y[:, None]
    base[..., 2] = (seed * 53) % 200
    out = np.repeat(base[None], n, axis=0)
    bar = max(w // 8, 4)
    for t in range(n):
        x = int((w - bar) * t / max(n - 1, 1))
        out[t, size // 4 : size // 2, x : x + bar] = (250, 230, 40)
    return out


def write_mp4(
    path: Path, frames: np.ndarray, fps: int = 10, codec: str = "libx264", gop: int | None = None
) -> Path:
    """Encode frames with PyAV: 'libx264' (H.264) or 'libsvtav1' (AV1, even dims >= 64)."""
    if codec not in av.codecs_available:
        pytest.skip(f"this PyAV build has no {codec} encoder")
    path.parent.mkdir(parents=True, exist_ok=True)
    with av.open(str(path), mode="w", format="mp4") as container:
        stream = container.add_stream(codec, rate=Fraction(fps))
        stream.width, stream.height, stream.pix_fmt = frames.shape[2], frames.shape[1], "yuv420p"
        if gop:
            stream.codec_context.gop_size = gop
        if codec == "libsvtav1":
            stream.options = {"preset": "12", "crf": "30"}
        else:
            stream.options = {"crf": "18", "preset": "veryfast"}
        for arr in frames:
            container.mux(stream.encode(av.VideoFrame.from_ndarray(arr, format="rgb24")))
        container.mux(stream.encode())
    return path


def encode_image(arr: np.ndarray, fmt: str = "PNG") -> bytes:
    buf = io.BytesIO()
    Image.fromarray(arr).save(buf, format=fmt)
    return buf.getvalue()


# ---------------------------------------------------------------------------- LeRobot


def _lerobot_features(cameras: list[str], size: int, dtype: str) -> dict:
    feats: dict = {
        "observation.state": {"dtype": "float32", "shape": [2], "names": None},
        "action": {"dtype": "float32", "shape": [2], "names": None},
        "timestamp": {"dtype": "float32", "shape": [1], "names": None},
        "frame_index": {"dtype": "int64", "shape": [1], "names": None},
        "episode_index": {"dtype": "int64", "shape": [1], "names": None},
        "index": {"dtype": "int64", "shape": [1], "names": None},
        "task_index": {"dtype": "int64", "shape": [1], "names": None},
    }
    for cam in cameras:
        feats[cam] = {
            "dtype": dtype,
            "shape": [size, size, 3],
            "names": ["height", "width", "channel"],
        }
    return feats


def _data_columns(ep: int, n: int, start: int, task_index: int, fps: int) -> dict:
    return {
        "observation.state": [[float(t), 0.0] for t in range(n)],
        "action": [[0.0, 1.0]] * n,
        "timestamp": [t / fps for t in range(n)],
        "frame_index": list(range(n)),
        "episode_index": [ep] * n,
        "index": list(range(start, start + n)),
        "task_index": [task_index] * n,
    }


def write_lerobot_v2(
    root: Path,
    lengths: tuple[int, ...] = (12, 9),
    tasks: tuple[str, ...] = ("pick up the cube", "open the drawer"),
    cameras: tuple[str, ...] = (CAMERA,),
    codec: str = "libx264",
    size: int = 64,
    fps: int = 10,
    images_in_parquet: bool = False,
) -> Path:
    """LeRobot v2.1: per-episode parquet + per-episode MP4 per camera (or PNGs in parquet)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    root.mkdir(parents=True, exist_ok=True)
    dtype = "image" if images_in_parquet else "video"
    info = {
        "codebase_version": "v2.1",
        "robot_type": "so100",
        "total_episodes": len(lengths),
        "total_frames": sum(lengths),
        "total_tasks": len(set(tasks)),
        "chunks_size": 1000,
        "fps": fps,
        "splits": {"train": f"0:{len(lengths)}"},
        "data_path": "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet",
        "video_path": None
        if images_in_parquet
        else "videos/chunk-{episode_chunk:03d}/{video_key}/episode_{episode_index:06d}.mp4",
        "features": _lerobot_features(list(cameras), size, dtype),
    }
    task_list = sorted(set(tasks), key=tasks.index)
    (root / "meta").mkdir(exist_ok=True)
    (root / "meta" / "info.json").write_text(json.dumps(info, indent=2))
    (root / "meta" / "tasks.jsonl").write_text(
        "".join(json.dumps({"task_index": i, "task": t}) + "\n" for i, t in enumerate(task_list))
    )
    lines, start = [], 0
    for ep, n in enumerate(lengths):
        task = tasks[ep % len(tasks)]
        lines.append(json.dumps({"episode_index": ep, "tasks": [task], "length": n}) + "\n")
        cols = _data_columns(ep, n, start, task_list.index(task), fps)
        for c, cam in enumerate(cameras):
            frames = frames_for(n, size, seed=ep * 10 + c)
            if images_in_parquet:
                cols[cam] = [{"bytes": encode_image(f), "path": None} for f in frames]
            else:
                rel = info["video_path"].format(episode_chunk=0, video_key=cam, episode_index=ep)
                write_mp4(root / rel, frames, fps=fps, codec=codec)
        path = root / info["data_path"].format(episode_chunk=0, episode_index=ep)
        path.parent.mkdir(parents=True, exist_ok=True)
        pq.write_table(pa.table(cols), path)
        start += n
    (root / "meta" / "episodes.jsonl").write_text("".join(lines))
    return root


@pytest.fixture
def make_lerobot_v2() -> Callable[..., Path]:
    """Fixture form of `write_lerobot_v2`."""
    return write_lerobot_v2


def write_lerobot_v3(
    root: Path,
    lengths: tuple[int, ...] = (12, 9, 7),
    tasks: tuple[str, ...] = ("stack the blocks", "wipe the table"),
    cameras: tuple[str, ...] = (CAMERA,),
    codec: str = "libsvtav1",
    size: int = 64,
    fps: int = 10,
) -> Path:
    """LeRobot v3.0: episodes concatenated in one data parquet and one MP4 per camera."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    root.mkdir(parents=True, exist_ok=True)
    info = {
        "codebase_version": "v3.0",
        "robot_type": "koch",
        "total_episodes": len(lengths),
        "total_frames": sum(lengths),
        "total_tasks": len(set(tasks)),
        "chunks_size": 1000,
        "data_files_size_in_mb": 100,
        "video_files_size_in_mb": 500,
        "fps": fps,
        "splits": {"train": f"0:{len(lengths)}"},
        "data_path": "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet",
        "video_path": "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4",
        "features": _lerobot_features(list(cameras), size, "video"),
    }
    task_list = sorted(set(tasks), key=tasks.index)
    (root / "meta").mkdir(exist_ok=True)
    (root / "meta" / "info.json").write_text(json.dumps(info, indent=2))
    # pandas writes the task strings as its index; mimic that column layout
    pq.write_table(
        pa.table({"task_index": list(range(len(task_list))), "__index_level_0__": task_list}),
        root / "meta" / "tasks.parquet",
    )
    data: dict[str, list] = {}
    episodes: dict[str, list] = {
        "episode_index": [],
        "tasks": [],
        "length": [],
        "data/chunk_index": [],
        "data/file_index": [],
        "dataset_from_index": [],
        "dataset_to_index": [],
    }
    for cam in cameras:
        for f in ("chunk_index", "file_index", "from_timestamp", "to_timestamp"):
            episodes[f"videos/{cam}/{f}"] = []
    all_frames = {cam: [] for cam in cameras}
    start = 0
    for ep, n in enumerate(lengths):
        task = tasks[ep % len(tasks)]
        for k, v in _data_columns(ep, n, start, task_list.index(task), fps).items():
            data.setdefault(k, []).extend(v)
        episodes["episode_index"].append(ep)
        episodes["tasks"].append([task])
        episodes["length"].append(n)
        episodes["data/chunk_index"].append(0)
        episodes["data/file_index"].append(0)
        episodes["dataset_from_index"].append(start)
        episodes["dataset_to_index"].append(start + n)
        for c, cam in enumerate(cameras):
            episodes[f"videos/{cam}/chunk_index"].append(0)
            episodes[f"videos/{cam}/file_index"].append(0)
            episodes[f"videos/{cam}/from_timestamp"].append(start / fps)
            episodes[f"videos/{cam}/to_timestamp"].append((start + n) / fps)
            all_frames[cam].append(frames_for(n, size, seed=ep * 10 + c))
        start += n
    data_path = root / info["data_path"].format(chunk_index=0, file_index=0)
    data_path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(pa.table(data), data_path)
    ep_path = root / "meta" / "episodes" / "chunk-000" / "file-000.parquet"
    ep_path.parent.mkdir(parents=True, exist_ok=True)
    episodes["stats/action/mean"] = [[0.0, 1.0]] * len(lengths)
    pq.write_table(pa.table(episodes), ep_path)
    for cam in cameras:
        rel = info["video_path"].format(video_key=cam, chunk_index=0, file_index=0)
        write_mp4(root / rel, np.concatenate(all_frames[cam]), fps=fps, codec=codec)
    return root


@pytest.fixture
def make_lerobot_v3() -> Callable[..., Path]:
    """Fixture form of `write_lerobot_v3`."""
    return write_lerobot_v3


# ---------------------------------------------------------------------------- RLDS


def _varint(v: int) -> bytes:
    v &= (1 << 64) - 1
    out = bytearray()
    while True:
        b = v & 0x7F
        v >>= 7
        if v:
            out.append(b | 0x80)
        else:
            out.append(b)
            return bytes(out)


def _field(num: int, payload: bytes) -> bytes:
    return _varint(num << 3 | 2) + _varint(len(payload)) + payload


def encode_feature(value: list) -> bytes:
    """A tf.train.Feature: bytes_list (1), float_list (2, packed) or int64_list (3, packed)."""
    if value and isinstance(value[0], bytes | str):
        items = b"".join(_field(1, v.encode() if isinstance(v, str) else v) for v in value)
        return _field(1, items)
    if value and isinstance(value[0], float):
        return _field(2, _field(1, struct.pack(f"<{len(value)}f", *value)))
    return _field(3, _field(1, b"".join(_varint(int(v)) for v in value)))


def encode_example(features: dict[str, list]) -> bytes:
    """A tf.train.Example {features: {feature: map<string, Feature>}}."""
    entries = b"".join(
        _field(1, _field(1, key.encode()) + _field(2, encode_feature(vals)))
        for key, vals in features.items()
    )
    return _field(1, entries)


def _masked_crc(data: bytes) -> int:
    from rover.io.tfrecord import masked_crc32c

    return masked_crc32c(data)


def write_tfrecord(path: Path, records: list[bytes]) -> Path:
    with open(path, "wb") as fh:
        for rec in records:
            header = struct.pack("<Q", len(rec))
            fh.write(header + struct.pack("<I", _masked_crc(header)))
            fh.write(rec + struct.pack("<I", _masked_crc(rec)))
    return path


def rlds_features_json(image_keys: tuple[str, ...], size: int, fmt: str) -> dict:
    def image(_k: str) -> dict:
        return {
            "pythonClassName": "tensorflow_datasets.core.features.image_feature.Image",
            "image": {
                "shape": {"dimensions": [str(size), str(size), "3"]},
                "dtype": "uint8",
                "encodingFormat": fmt,
            },
        }

    def tensor(shape: list[str], dtype: str) -> dict:
        return {
            "pythonClassName": "tensorflow_datasets.core.features.tensor_feature.Tensor",
            "tensor": {"shape": {"dimensions": shape}, "dtype": dtype, "encoding": "none"},
        }

    fd = "tensorflow_datasets.core.features.features_dict.FeaturesDict"
    TEXT = "tensorflow_datasets.core.features.text_feature.Text"  # noqa: N806
    obs = {k: image(k) for k in image_keys}
    obs["state"] = tensor(["2"], "float32")
    step = {
        "observation": {"pythonClassName": fd, "featuresDict": {"features": obs}},
        "action": tensor(["2"], "float32"),
        "is_first": {
            "pythonClassName": "tensorflow_datasets.core.features.scalar.Scalar",
            "tensor": {"shape": {}, "dtype": "bool", "encoding": "none"},
        },
        "language_instruction": {
            "pythonClassName": "tensorflow_datasets.core.features.text_feature.Text",
            "text": {},
        },
    }
    return {
        "pythonClassName": fd,
        "featuresDict": {
            "features": {
                "steps": {
                    "pythonClassName": "tensorflow_datasets.core.features.dataset_feature.Dataset",
                    "sequence": {
                        "feature": {"pythonClassName": fd, "featuresDict": {"features": step}},
                        "length": "-1",
                    },
                },
                "episode_metadata": {
                    "pythonClassName": fd,
                    "featuresDict": {
                        "features": {
                            "file_path": {
                                "pythonClassName": TEXT,
                                "text": {},
                            },
                        }
                    },
                },
            }
        },
    }


def write_rlds(
    root: Path,
    shards: tuple[tuple[int, ...], ...] = ((10, 8), (6,)),
    instructions: tuple[str, ...] = ("put the spoon in the pot", "close the drawer"),
    image_keys: tuple[str, ...] = ("image", "wrist_image"),
    size: int = 64,
    fmt: str = "jpeg",
    name: str = "toy_dataset",
) -> Path:
    """An OpenX-style RLDS folder: features.json + dataset_info.json + TFRecord shards."""
    root.mkdir(parents=True, exist_ok=True)
    (root / "features.json").write_text(json.dumps(rlds_features_json(image_keys, size, fmt)))
    (root / "dataset_info.json").write_text(json.dumps({"name": name, "version": "0.1.0"}))
    ep = 0
    for s, lengths in enumerate(shards):
        records = []
        for n in lengths:
            feats: dict[str, list] = {}
            for c, key in enumerate(image_keys):
                frames = frames_for(n, size, seed=ep * 10 + c)
                feats[f"steps/observation/{key}"] = [
                    encode_image(f, "JPEG" if fmt == "jpeg" else "PNG") for f in frames
                ]
            feats["steps/observation/state"] = [float(t) for t in range(n) for _ in (0, 1)]
            feats["steps/action"] = [0.5] * (2 * n)
            feats["steps/is_first"] = [1] + [0] * (n - 1)
            feats["steps/language_instruction"] = [instructions[ep % len(instructions)]] * n
            feats["episode_metadata/file_path"] = [f"/raw/ep{ep}.h5"]
            records.append(encode_example(feats))
            ep += 1
        write_tfrecord(root / f"{name}-train.tfrecord-{s:05d}-of-{len(shards):05d}", records)
    return root


@pytest.fixture
def make_rlds() -> Callable[..., Path]:
    """Fixture form of `write_rlds`."""
    return write_rlds


# ---------------------------------------------------------------------------- HDF5


def write_robomimic(
    path: Path,
    lengths: tuple[int, ...] = (11, 8),
    cameras: tuple[str, ...] = ("agentview", "robot0_eye_in_hand"),
    size: int = 48,
    with_images: bool = True,
    task: str = "lift the cube",
) -> Path:
    """A robomimic/RoboCasa-style demo file: data/demo_N/obs/<camera>_image (N, H, W, 3)."""
    import h5py

    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as f:
        data = f.create_group("data")
        data.attrs["env_args"] = json.dumps(
            {"env_name": "Lift", "type": 1, "env_kwargs": {"camera_names": list(cameras)}}
        )
        data.attrs["total"] = sum(lengths)
        for i, n in enumerate(lengths):
            demo = data.create_group(f"demo_{i}")
            demo.attrs["num_samples"] = n
            demo.attrs["ep_meta"] = json.dumps({"lang": task})
            demo.create_dataset("actions", data=np.zeros((n, 7), dtype=np.float32))
            demo.create_dataset("states", data=np.zeros((n, 10), dtype=np.float64))
            obs = demo.create_group("obs")
            obs.create_dataset("robot0_eef_pos", data=np.zeros((n, 3), dtype=np.float64))
            if with_images:
                for c, cam in enumerate(cameras):
                    obs.create_dataset(f"{cam}_image", data=frames_for(n, size, seed=i * 10 + c))
    return path


@pytest.fixture
def make_robomimic() -> Callable[..., Path]:
    """Fixture form of `write_robomimic`."""
    return write_robomimic


# ---------------------------------------------------------------------------- a model's replies


def _texts(body: dict, role: str | None = None) -> list[str]:
    out = []
    for m in body.get("messages", []):
        if role is not None and m.get("role") != role:
            continue
        content = m.get("content")
        if isinstance(content, str):
            out.append(content)
        else:
            out += [p.get("text", "") for p in content or [] if p.get("type") == "text"]
    return out


def model_like_answer(body: dict) -> str:
    """Replies to rover's prompts the way a chat model writes them: markdown, prose, no meta.

    For `OpenAICompatServer.answer`: it sees only what goes over the wire (texts and
    images), as a real server does. GVL frames get rising percentages by label; ROVER
    decomposes the task once, then raises each subtask's percentage by 40 points from
    the previous frame's, and says the task is complete when asked about the parent.
    """
    import re

    system = " ".join(_texts(body, "system"))
    user = " ".join(_texts(body, "user"))
    if "random order" in system or "random order" in user:
        labels = sorted({int(n) for n in re.findall(r"Frame (\d+):", user)})
        return "\n\n".join(
            f"**Frame {n}:**\nFrame description: The arm is over the table.\n"
            f"Task completion percentage: {min(10 * n, 100)}%"
            for n in labels or [1]
        )
    if "The robot has completed:" in system + user:
        return "Task complete"
    previous = re.findall(r"completion percentage: (-?\d+(?:\.\d+)?)%", user)
    if not previous and "The robot needs to" in system and "grasp the object" not in system:
        return "Frame description: The gripper is open.\nThe robot needs to: grasp the object"
    p = float(previous[-1]) if previous else 0.0
    return (
        "Looking at the current frame, the arm has moved closer.\n\n"
        "**Frame description:** The gripper is near the object.\n"
        f"**Subtask completion percentage:** {min(p + 40, 100):.0f}%"
    )
