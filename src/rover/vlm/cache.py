"""The persistent response cache: one SQLite file shared by every run and process.

A rerun of the same method on the same frames with the same model and sampling settings
costs nothing: the answer comes back from disk with `cached=True`. The key is a hash of
everything that can change an answer: backend kind, endpoint (the base URL, without
credentials: two vLLM deployments serving the same model name are different models),
model, prompt fingerprint (text and image bytes), sampling parameters and output budget,
backend extras — never of an API key, which is not part of any answer. WAL mode and a
busy timeout let many threads and processes write at once; each thread has its own
connection (sqlite3 connections must not be shared across threads).
"""

from __future__ import annotations

import hashlib
import json
import sqlite3
import threading
import time
from pathlib import Path
from typing import Any

from rover.errors import InputError
from rover.vlm.types import Completion, SamplingParams, Usage

CACHE_SCHEMA_VERSION = 2  # 2: the endpoint is part of the key
BUSY_TIMEOUT_MS = 30_000

_SCHEMA = """
CREATE TABLE IF NOT EXISTS responses (
    key TEXT PRIMARY KEY,
    backend TEXT NOT NULL,
    model TEXT NOT NULL,
    text TEXT NOT NULL,
    usage TEXT NOT NULL,
    latency_s REAL NOT NULL,
    created_at REAL NOT NULL
)
"""


def cache_key(
    backend: str,
    model: str,
    fingerprint: str,
    params: SamplingParams,
    extra: dict[str, Any] | None = None,
    *,
    endpoint: str = "",
) -> str:
    """The hash that identifies one answer: same key, same question to the same model."""
    payload = {
        "v": CACHE_SCHEMA_VERSION,
        "backend": backend,
        "endpoint": endpoint,
        "model": model,
        "prompt": fingerprint,
        "params": params.model_dump(mode="json"),
        "extra": extra or {},
    }
    return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()


class ResponseCache:
    """SQLite-backed map from cache key to completion; safe under concurrent writers."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path).expanduser()
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"cannot create the cache folder {self.path.parent}: {exc}") from exc
        self._local = threading.local()
        self._conn()  # create the file and schema now, so a bad path fails early

    def _conn(self) -> sqlite3.Connection:
        conn = getattr(self._local, "conn", None)
        if conn is None:
            try:
                conn = sqlite3.connect(
                    self.path, timeout=BUSY_TIMEOUT_MS / 1000, isolation_level=None
                )
                conn.execute(f"PRAGMA busy_timeout={BUSY_TIMEOUT_MS}")
                conn.execute("PRAGMA journal_mode=WAL")
                conn.execute("PRAGMA synchronous=NORMAL")
                conn.execute(_SCHEMA)
            except sqlite3.DatabaseError as exc:
                raise InputError(
                    f"response cache {self.path} is unusable ({exc}); delete it or pass --no-cache"
                ) from exc
            self._local.conn = conn
        return conn

    def get(self, key: str) -> Completion | None:
        """The cached completion for `key` (marked cached, zero latency), or None."""
        row = (
            self._conn()
            .execute(
                "SELECT backend, model, text, usage, latency_s FROM responses WHERE key = ?",
                (key,),
            )
            .fetchone()
        )
        if row is None:
            return None
        backend, model, text, usage, _latency = row
        return Completion(
            text=text,
            usage=Usage.model_validate_json(usage),
            latency_s=0.0,
            cached=True,
            backend=backend,
            model=model,
        )

    def put(self, key: str, completion: Completion) -> None:
        """Store (or replace) the answer for `key`."""
        self._conn().execute(
            "INSERT OR REPLACE INTO responses (key, backend, model, text, usage, latency_s,"
            " created_at) VALUES (?, ?, ?, ?, ?, ?, ?)",
            (
                key,
                completion.backend,
                completion.model,
                completion.text,
                completion.usage.model_dump_json(),
                completion.latency_s,
                time.time(),
            ),
        )

    def __len__(self) -> int:
        return int(self._conn().execute("SELECT COUNT(*) FROM responses").fetchone()[0])

    def close(self) -> None:
        """Close this thread's connection (others close when their threads end)."""
        conn = getattr(self._local, "conn", None)
        if conn is not None:
            conn.close()
            self._local.conn = None
