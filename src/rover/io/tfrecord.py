"""TFRecord files and `tf.train.Example` protos, read without TensorFlow.

A TFRecord file is a sequence of records, each framed as::

    uint64 length (little endian) | uint32 masked crc32c(length) | data | uint32 masked crc32c(data)

The length CRC is always checked (it catches files that are not TFRecords at all, and
truncation); the data CRC costs a pure-Python pass over every byte, so it is optional.

`tf.train.Example` and `SequenceExample` are decoded with a minimal protobuf
wire-format reader: only the handful of message types they use is needed.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rover.errors import InputError


def _crc32c_table() -> list[int]:
    table = []
    for i in range(256):
        crc = i
        for _ in range(8):
            crc = (crc >> 1) ^ 0x82F63B78 if crc & 1 else crc >> 1
        table.append(crc)
    return table


_TABLE = _crc32c_table()


def crc32c(data: bytes) -> int:
    """CRC-32C (Castagnoli), the checksum TFRecord uses."""
    crc = 0xFFFFFFFF
    table = _TABLE
    for b in data:
        crc = table[(crc ^ b) & 0xFF] ^ (crc >> 8)
    return crc ^ 0xFFFFFFFF


def masked_crc32c(data: bytes) -> int:
    crc = crc32c(data)
    return (((crc >> 15) | (crc << 17)) + 0xA282EAD8) & 0xFFFFFFFF


@dataclass(frozen=True)
class RecordSpan:
    """Where one record's data lies in its file."""

    offset: int
    length: int


def scan_records(path: Path) -> list[RecordSpan]:
    """Locate every record by reading only the 12-byte headers (data is skipped)."""
    spans: list[RecordSpan] = []
    size = path.stat().st_size
    with open(path, "rb") as fh:
        pos = 0
        while pos < size:
            header = fh.read(12)
            if len(header) < 12:
                raise InputError(f"{path}: truncated TFRecord header at byte {pos}")
            (length,) = struct.unpack("<Q", header[:8])
            (crc,) = struct.unpack("<I", header[8:])
            if masked_crc32c(header[:8]) != crc:
                raise InputError(
                    f"{path}: bad TFRecord length checksum at byte {pos} (not a TFRecord file?)"
                )
            if pos + 12 + length + 4 > size:
                raise InputError(
                    f"{path}: record {len(spans)} truncated (needs {length} bytes at byte {pos})"
                )
            spans.append(RecordSpan(pos + 12, length))
            pos += 12 + length + 4
            fh.seek(pos)
    return spans


def read_record(path: Path, span: RecordSpan, verify: bool = False) -> bytes:
    with open(path, "rb") as fh:
        fh.seek(span.offset)
        data = fh.read(span.length + 4)
    if len(data) < span.length + 4:
        raise InputError(f"{path}: record at byte {span.offset} truncated")
    payload = data[: span.length]
    if verify:
        (crc,) = struct.unpack("<I", data[span.length :])
        if masked_crc32c(payload) != crc:
            raise InputError(f"{path}: record at byte {span.offset} fails its data checksum")
    return payload


# ------------------------------------------------------------------ protobuf wire format


def _varint(buf: bytes, pos: int) -> tuple[int, int]:
    result = shift = 0
    while True:
        if pos >= len(buf):
            raise ValueError("truncated varint")
        b = buf[pos]
        pos += 1
        result |= (b & 0x7F) << shift
        if not b & 0x80:
            return result, pos
        shift += 7
        if shift > 63:
            raise ValueError("varint too long")


def iter_fields(buf: bytes):
    """Yield (field number, wire type, value) of a serialized message.

    Length-delimited values come back as bytes, varints as int, fixed32/64 as bytes.
    """
    pos, end = 0, len(buf)
    while pos < end:
        key, pos = _varint(buf, pos)
        num, wire = key >> 3, key & 7
        if wire == 0:
            value, pos = _varint(buf, pos)
        elif wire == 2:
            n, pos = _varint(buf, pos)
            if pos + n > end:
                raise ValueError("truncated length-delimited field")
            value, pos = buf[pos : pos + n], pos + n
        elif wire == 5:
            value, pos = buf[pos : pos + 4], pos + 4
        elif wire == 1:
            value, pos = buf[pos : pos + 8], pos + 8
        else:
            raise ValueError(f"unsupported wire type {wire}")
        if pos > end:
            raise ValueError("truncated field")
        yield num, wire, value


Value = list[bytes] | np.ndarray  # bytes_list, or float32 / int64 array
KIND_NAMES = {1: "bytes_list", 2: "float_list", 3: "int64_list"}


@dataclass
class Feature:
    """One tf.train.Feature: `kind` is bytes_list, float_list or int64_list."""

    kind: str
    value: Value


def _decode_feature(buf: bytes) -> Feature:
    for num, _wire, payload in iter_fields(buf):
        if num == 1:
            return Feature("bytes_list", [bytes(v) for n, _w, v in iter_fields(payload) if n == 1])
        if num == 2:
            parts = []
            for n, _w, v in iter_fields(payload):
                if n == 1:
                    parts.append(np.frombuffer(v, dtype="<f4"))  # packed (w=2) or single (w=5)
            arr = np.concatenate(parts) if parts else np.zeros(0, np.float32)
            return Feature("float_list", arr.astype(np.float32))
        if num == 3:
            vals: list[int] = []
            for n, w, v in iter_fields(payload):
                if n != 1:
                    continue
                if w == 0:
                    vals.append(v)
                else:
                    p = 0
                    while p < len(v):
                        x, p = _varint(v, p)
                        vals.append(x)
            arr = np.array([x - (1 << 64) if x >= 1 << 63 else x for x in vals], dtype=np.int64)
            return Feature("int64_list", arr)
    return Feature("bytes_list", [])  # an empty Feature


def _decode_features_map(buf: bytes) -> dict[str, Feature]:
    out: dict[str, Feature] = {}
    for num, _w, entry in iter_fields(buf):
        if num != 1:
            continue
        key, value = "", b""
        for n, _w2, v in iter_fields(entry):
            if n == 1:
                key = bytes(v).decode("utf-8", errors="replace")
            elif n == 2:
                value = v
        out[key] = _decode_feature(value)
    return out


def decode_example(buf: bytes) -> tuple[dict[str, Feature], dict[str, list[Feature]]]:
    """(features, feature_lists) of an Example (lists empty) or SequenceExample.

    Both messages keep their (context) Features in field 1; only SequenceExample has
    field 2, FeatureLists {map<string, FeatureList{repeated Feature}>}.
    """
    features: dict[str, Feature] = {}
    lists: dict[str, list[Feature]] = {}
    for num, wire, payload in iter_fields(buf):
        if wire != 2:
            continue
        if num == 1:
            features.update(_decode_features_map(payload))
        elif num == 2:
            for n, _w, entry in iter_fields(payload):
                if n != 1:
                    continue
                key, flist = "", []
                for n2, _w2, v in iter_fields(entry):
                    if n2 == 1:
                        key = bytes(v).decode("utf-8", errors="replace")
                    elif n2 == 2:
                        flist = [_decode_feature(f) for n3, _w3, f in iter_fields(v) if n3 == 1]
                lists[key] = flist
    return features, lists
