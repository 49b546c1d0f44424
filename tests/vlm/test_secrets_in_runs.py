"""No secret of any shape reaches a file or stream of a real run (issue 15, item 5).

One `rover eval` against a loopback server, with every way a secret can travel: a key in
the environment, credentials in the base URL (which httpx sends as Basic auth), a server
that echoes the key and an `Authorization: Basic` header inside 200 answers, inside
retried 500 and 429 bodies, and inside a 401 body long enough to be truncated. Then every
byte of every file written (run directory, response cache with its WAL, cassette) and
both streams are searched.
"""

from __future__ import annotations

import base64
import sys

import numpy as np
import pytest

from rover import cli
from rover.episode import Episode, FrameFacts, GroundTruth
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode
from rover.vlm.testing import OpenAICompatServer, Reply

KEY = "sk-runSECRET0123456789abcdefXYZ"
URL_PW = "url-Pass-w0rd-777"
BASIC_TOKEN = "dXNlcjp1cmwtUGFzcy13MHJkLTc3Nw=="
# httpx turns URL credentials into this header: it must not be stored either
URL_BASIC = base64.b64encode(f"alice:{URL_PW}".encode()).decode()
SECRETS = (KEY, URL_PW, BASIC_TOKEN, URL_BASIC)


def _dataset(root) -> None:
    write_dataset_info(root, DatasetInfo(views=["left"]))
    for k in range(2):
        n = 4
        frames = np.full((n, 24, 24, 3), 30 * k, dtype=np.uint8)
        frames[:, :, :, 1] = np.arange(n)[:, None, None] * 40
        write_episode(
            root,
            Episode(
                id=f"ep{k}",
                task="lift the cube",
                fps=10,
                frame_indices=list(range(n)),
                view_names=["left"],
                truth=GroundTruth(
                    progress=[t / (n - 1) for t in range(n)], facts=[FrameFacts()] * n
                ),
                views={"left": frames},
            ),
        )


def _echo(body) -> str:
    return (
        f"Frame description: the server saw key {KEY} and Authorization: Basic {BASIC_TOKEN}.\n"
        "Subtask completion percentage: 50%"
    )


def test_no_secret_reaches_any_file_or_stream(tmp_path, monkeypatch, capsys):
    _dataset(tmp_path / "ds")
    monkeypatch.setenv("OPENAI_API_KEY", KEY)
    monkeypatch.setenv("ROVER_CACHE_DIR", str(tmp_path / "cache"))
    with OpenAICompatServer() as server:
        server.answer = _echo
        server.script(
            Reply(status=500, text=f"upstream rejected Authorization: Basic {BASIC_TOKEN}"),
            Reply(status=429, text=f"slow down {KEY}", headers={"retry-after": "0"}),
        )
        url = f"http://alice:{URL_PW}@127.0.0.1:{server.port}/v1"
        argv = [
            "rover", "eval", "--dataset", str(tmp_path / "ds"), "--methods", "rover",
            "--backend", f"openai:m@{url}", "--judge", "rule", "--answerer", "none",
            "--out", str(tmp_path / "run"), "--record", str(tmp_path / "cassette.jsonl"),
            "--max-retries", "2", "--concurrency", "1",
        ]  # fmt: skip
        monkeypatch.setattr(sys, "argv", argv)
        # the first episode's 4 calls succeed (echoing secrets); then a 401 fails the second
        leaky_401 = "x" * 280 + f" Authorization: Basic {BASIC_TOKEN} {KEY}"  # cut at 300
        server.script(*[Reply() for _ in range(4)], *[Reply(status=401, text=leaky_401)] * 40)
        with pytest.raises(SystemExit) as exit_info:
            cli.main()
        assert exit_info.value.code == 1  # a unit failed: the run says so in its status
        assert server.keys_seen[0] == f"Basic {URL_BASIC}"  # the URL's credentials were used
    streams = capsys.readouterr()
    written = [p for p in tmp_path.rglob("*") if p.is_file() and "ds" not in p.parts]
    names = {p.name for p in written}
    assert {"run.json", "errors.jsonl", "cassette.jsonl", "responses.sqlite"} <= names
    assert "metrics.json" in names and any(p.suffix == ".md" for p in written)
    for secret in SECRETS:
        assert secret not in streams.out and secret not in streams.err
        for path in written:
            assert secret.encode() not in path.read_bytes(), (secret, path)
    # the answers themselves survived, scrubbed
    assert "<redacted>" in (tmp_path / "cassette.jsonl").read_text()
    assert "401" in (tmp_path / "run" / "errors.jsonl").read_text()
    assert "1 of 2 work unit(s) failed" in " ".join(streams.err.split())
