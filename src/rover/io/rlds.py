"""OpenX-Embodiment RLDS episodes (TFDS TFRecord shards), read without TensorFlow.

A TFDS-built RLDS dataset version folder looks like::

    <dataset>/<version>/features.json          the feature tree (FeaturesDict / Dataset)
    <dataset>/<version>/dataset_info.json      name, version, splits
    <dataset>/<version>/<dataset>-train.tfrecord-00000-of-00064

Each record is one episode serialized as a `tf.train.Example` whose keys flatten the
tree with "/": `steps/observation/image` is a bytes_list holding one JPEG/PNG per step,
`steps/language_instruction` one string per step, `episode_metadata/...` per-episode
values. features.json says which step fields are images and which are text; without
it, image fields are recognised by their JPEG/PNG magic bytes.
"""

from __future__ import annotations

import io
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
from PIL import Image, UnidentifiedImageError

from rover.episode import Episode
from rover.errors import InputError
from rover.io.frames import stack_frames, to_rgb_array
from rover.io.plain import sample_positions
from rover.io.source import SourceReader
from rover.io.tfrecord import Feature, RecordSpan, decode_example, read_record, scan_records

DEFAULT_FPS = 10.0  # RLDS does not store a frame rate; OpenX control rates are 3-30 Hz
_SHARD = re.compile(r"-(?P<split>[A-Za-z0-9_]+)\.tfrecord-(?P<shard>\d+)-of-\d+$")
_MAGIC = (b"\xff\xd8\xff", b"\x89PNG")
_NOT_COLOR = ("depth", "seg", "mask", "flow")  # image fields a VLM should not get by default
_LANGUAGE_HINTS = (
    "language_instruction",
    "natural_language_instruction",
    "instruction",
    "language",
    "task",
)


def schema_fields(features_json: dict[str, Any]) -> dict[str, str]:
    """Flattened feature path -> kind ("image", "text", "tensor", "other")."""
    out: dict[str, str] = {}

    def walk(node: Any, prefix: str) -> None:
        if not isinstance(node, dict):
            return
        if "featuresDict" in node:
            for key, child in (node["featuresDict"].get("features") or {}).items():
                walk(child, f"{prefix}/{key}" if prefix else key)
        elif "sequence" in node:
            walk(node["sequence"].get("feature"), prefix)
        elif "image" in node or str(node.get("pythonClassName", "")).endswith("Image"):
            out[prefix] = "image"
        elif "text" in node:
            out[prefix] = "text"
        elif "tensor" in node:
            dtype = str((node.get("tensor") or {}).get("dtype", ""))
            out[prefix] = "text" if dtype == "string" else "tensor"
        else:
            out[prefix] = "other"

    walk(features_json, "")
    return out


class RLDSSource(SourceReader):
    """Episodes of an RLDS folder (or one shard); `view`/`?camera=` picks the image field."""

    kind = "rlds"
    extra_keys = frozenset({"split", "verify"})

    def __init__(self, path: Path, **kwargs: Any) -> None:
        super().__init__(path, **kwargs)
        if self.path.is_file():
            self.folder, self.shards = self.path.parent, [self.path]
        else:
            self.folder = _version_folder(self.path)
            self.shards = sorted(
                p
                for p in self.folder.iterdir()
                if p.is_file() and ".tfrecord" in p.name and not p.name.endswith(".json")
            )
        split = self.options.get("split")
        if split:
            self.shards = [p for p in self.shards if f"-{split}.tfrecord" in p.name]
        if not self.shards:
            raise InputError(
                f"{self.folder}: no TFRecord shards found"
                + (f" for split {split!r}" if split else " (expected *.tfrecord-*-of-* files)")
            )
        self.verify = self.options.get("verify", "0").lower() in ("1", "true", "yes")
        self.schema = self._load_schema()
        self.dataset_name = self._dataset_name()
        self._spans: dict[Path, list[RecordSpan]] = {}

    @property
    def dataset(self) -> str:
        return self.dataset_name

    def _load_schema(self) -> dict[str, str] | None:
        path = self.folder / "features.json"
        if not path.exists():
            return None
        try:
            return schema_fields(json.loads(path.read_text()))
        except (json.JSONDecodeError, UnicodeDecodeError, AttributeError) as exc:
            raise InputError(f"{path}: invalid features.json ({exc.__class__.__name__})") from exc

    def _dataset_name(self) -> str:
        info = self.folder / "dataset_info.json"
        if info.exists():
            try:
                name = json.loads(info.read_text()).get("name")
                if name:
                    return str(name)
            except (json.JSONDecodeError, AttributeError):
                pass
        if re.fullmatch(r"\d+\.\d+\.\d+", self.folder.name):
            return self.folder.parent.name
        return self.folder.name

    # ---- listing ---------------------------------------------------------------------

    def _spans_of(self, shard: Path) -> list[RecordSpan]:
        if shard not in self._spans:
            self._spans[shard] = scan_records(shard)
        return self._spans[shard]

    def _shard_label(self, i: int, shard: Path) -> str:
        m = _SHARD.search(shard.name)
        return f"{m['split']}-{m['shard']}" if m else f"{i:05d}"

    def _episode_ids(self) -> list[str]:
        ids = []
        for i, shard in enumerate(self.shards):
            label = self._shard_label(i, shard)
            ids.extend(f"{label}-{k:04d}" for k in range(len(self._spans_of(shard))))
        return ids

    def _locate(self, episode_id: str) -> tuple[Path, int]:
        label, _, k = episode_id.rpartition("-")
        for i, shard in enumerate(self.shards):
            if self._shard_label(i, shard) == label and k.isdigit():
                if int(k) < len(self._spans_of(shard)):
                    return shard, int(k)
        raise InputError(f"{self.folder}: no episode {episode_id!r}")

    # ---- reading ---------------------------------------------------------------------

    def _read(self, episode_id: str, frames: int | None) -> Episode:
        shard, k = self._locate(episode_id)
        raw = read_record(shard, self._spans_of(shard)[k], verify=self.verify)
        try:
            features, lists = decode_example(raw)
        except ValueError as exc:
            raise InputError(
                f"{shard}: record {k} is not a valid tf.train.Example ({exc})"
            ) from exc
        steps = _step_values(features, lists)
        where = f"{shard}: record {k}"
        cameras = self._cameras(steps, where)
        camera = self._pick_camera(cameras, where)
        feature = steps[camera]
        if feature.kind != "bytes_list":
            raise InputError(
                f"{where}: feature {camera!r} should hold encoded images (bytes_list), "
                f"found {feature.kind}"
            )
        images: list[bytes] = feature.value  # type: ignore[assignment]
        positions = sample_positions(len(images), frames)
        pixels = stack_frames(
            [_decode_image(images[p], where, camera, p) for p in positions],
            f"{where}: feature {camera!r}",
        )
        return Episode(
            id=episode_id,
            task=self.task if self.task is not None else self._instruction(steps, features),
            source=f"rlds:{shard}",
            fps=self.fps or DEFAULT_FPS,
            frame_indices=positions,
            view_names=[_short(c) for c in cameras],
            default_view=_short(camera),
            views={_short(camera): pixels},
            extra={
                "total_frames": len(images),
                "dataset": self.dataset_name,
                "record": f"{shard.name}#{k}",
            },
        )

    def _cameras(self, steps: dict[str, Feature], where: str) -> list[str]:
        if self.schema is not None:
            cams = [
                k for k, kind in self.schema.items() if kind == "image" and k.startswith("steps/")
            ]
            missing = [c for c in cams if c not in steps]
            if cams and len(missing) == len(cams):
                raise InputError(f"{where}: no feature {cams[0]!r} (listed in features.json)")
            cams = [c for c in cams if c in steps]
        else:
            cams = [
                k
                for k, f in steps.items()
                if f.kind == "bytes_list" and f.value and bytes(f.value[0][:4]).startswith(_MAGIC)
            ]
        if not cams:
            raise InputError(f"{where}: no image feature among the step fields")
        return cams

    def _pick_camera(self, cameras: list[str], where: str) -> str:
        if self.view is None:
            exact = [c for c in cameras if _short(c) == "image"]
            color = [c for c in cameras if not any(w in _short(c) for w in _NOT_COLOR)]
            return (exact or color or cameras)[0]
        for c in cameras:
            if self.view in (c, _short(c), c.removeprefix("steps/")):
                return c
        raise InputError(
            f"{where}: no image feature {self.view!r}; cameras: "
            + ", ".join(_short(c) for c in cameras)
        )

    def _instruction(self, steps: dict[str, Feature], features: dict[str, Feature]) -> str:
        texts = [k for k, kind in (self.schema or {}).items() if kind == "text"]
        candidates = list(steps) + list(features)
        for hint in _LANGUAGE_HINTS:
            for key in texts + candidates:
                leaf = key.rsplit("/", 1)[-1]
                if hint not in leaf or "embedding" in leaf:
                    continue
                feat = steps.get(key) or features.get(key)
                if feat is None or feat.kind != "bytes_list":
                    continue
                for v in feat.value:
                    text = bytes(v).decode("utf-8", errors="replace").strip()
                    if text:
                        return text
        return ""


def _step_values(
    features: dict[str, Feature], lists: dict[str, list[Feature]]
) -> dict[str, Feature]:
    """Per-step fields as one Feature each (SequenceExample lists are concatenated)."""
    steps = {k: f for k, f in features.items() if k.startswith("steps/")}
    for key, flist in lists.items():
        name = key if key.startswith("steps/") else f"steps/{key}"
        if flist and all(f.kind == "bytes_list" for f in flist):
            steps[name] = Feature("bytes_list", [b for f in flist for b in f.value])
        elif flist:
            steps[name] = Feature(
                flist[0].kind, np.concatenate([np.asarray(f.value) for f in flist])
            )
    return steps


def _decode_image(data: bytes, where: str, camera: str, step: int) -> np.ndarray:
    try:
        with Image.open(io.BytesIO(data)) as img:
            return to_rgb_array(img)
    except (UnidentifiedImageError, OSError) as exc:
        raise InputError(
            f"{where}: feature {camera!r} step {step} is not a JPEG/PNG image"
        ) from exc


def _short(key: str) -> str:
    return key.rsplit("/", 1)[-1]


def _version_folder(path: Path) -> Path:
    """The folder holding the shards: PATH itself, or its single version subfolder."""
    if (path / "features.json").exists() or any(path.glob("*.tfrecord*")):
        return path
    subs = sorted(p for p in path.iterdir() if p.is_dir() and any(p.glob("*.tfrecord*")))
    if len(subs) == 1:
        return subs[0]
    if not subs:
        raise InputError(f"{path}: no TFRecord shards and no features.json (not an RLDS folder)")
    raise InputError(
        f"{path}: several versions ({', '.join(p.name for p in subs)}); name one in the path"
    )
