"""The SQLite response cache: keys, persistence, and many concurrent writers."""

from __future__ import annotations

import subprocess
import sys
import threading

import pytest

from rover.errors import InputError
from rover.vlm import BackendConfig, Completion, SamplingParams, Usage, default_cache_path
from rover.vlm.cache import ResponseCache, cache_key


def _completion(text: str) -> Completion:
    usage = Usage(prompt_tokens=10, completion_tokens=2, source="reported")
    return Completion(text=text, usage=usage, latency_s=1.5, backend="openai", model="m")


def test_key_changes_with_every_ingredient():
    base = cache_key("openai", "m", "fp", SamplingParams())
    assert base == cache_key("openai", "m", "fp", SamplingParams())
    assert base != cache_key("gemini", "m", "fp", SamplingParams())
    assert base != cache_key("openai", "m2", "fp", SamplingParams())
    assert base != cache_key("openai", "m", "fp2", SamplingParams())
    assert base != cache_key("openai", "m", "fp", SamplingParams(temperature=0.7))
    assert base != cache_key("openai", "m", "fp", SamplingParams(), {"detail": "low"})


def test_round_trip_survives_reopen(tmp_path):
    path = tmp_path / "sub" / "responses.sqlite"
    ResponseCache(path).put("k", _completion("hello"))
    hit = ResponseCache(path).get("k")
    assert hit is not None
    assert (hit.text, hit.cached, hit.latency_s, hit.usage.source) == (
        "hello",
        True,
        0.0,
        "reported",
    )
    assert ResponseCache(path).get("other") is None


def test_default_path_follows_env(monkeypatch, tmp_path):
    monkeypatch.setenv("ROVER_CACHE_DIR", str(tmp_path / "c"))
    assert default_cache_path() == tmp_path / "c" / "responses.sqlite"
    assert BackendConfig().resolved_cache_path() == tmp_path / "c" / "responses.sqlite"
    assert BackendConfig(cache_path=tmp_path / "x.db").resolved_cache_path() == tmp_path / "x.db"
    monkeypatch.delenv("ROVER_CACHE_DIR")
    assert default_cache_path().parts[-3:] == (".cache", "rover", "responses.sqlite")


def test_corrupt_cache_file_is_a_clear_error(tmp_path):
    path = tmp_path / "responses.sqlite"
    path.write_bytes(b"this is not a database" * 100)
    with pytest.raises(InputError, match="--no-cache"):
        ResponseCache(path)


_WRITER = """
import sys
from rover.vlm.cache import ResponseCache
from rover.vlm.types import Completion
cache = ResponseCache(sys.argv[1])
for i in range(40):
    cache.put(f"proc{sys.argv[2]}-{i}", Completion(text=f"p{sys.argv[2]}-{i}"))
"""


def test_sixteen_concurrent_writers(tmp_path):
    """12 threads (some sharing one cache object) and 4 processes write at the same time."""
    path = tmp_path / "responses.sqlite"
    shared = ResponseCache(path)
    procs = [subprocess.Popen([sys.executable, "-c", _WRITER, str(path), str(n)]) for n in range(4)]
    errors: list[BaseException] = []
    start = threading.Barrier(12)

    def write(n: int) -> None:
        try:
            cache = shared if n % 2 else ResponseCache(path)
            start.wait()
            for i in range(40):
                cache.put(f"thread{n}-{i}", _completion(f"t{n}-{i}"))
                assert cache.get(f"thread{n}-{i}").text == f"t{n}-{i}"
        except BaseException as exc:  # surfaced below
            errors.append(exc)

    threads = [threading.Thread(target=write, args=(n,)) for n in range(12)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert [p.wait(timeout=120) for p in procs] == [0, 0, 0, 0]
    assert not errors
    fresh = ResponseCache(path)
    assert len(fresh) == 16 * 40
    assert fresh.get("thread7-39").text == "t7-39"
    assert fresh.get("proc3-0").text == "p3-0"
