"""Fixtures for the evaluation tests: small real datasets on disk and a loopback VLM server."""

from __future__ import annotations

import json
import re
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from rover.episode import Episode, FrameFacts, ObjectFacts, QAItem
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode


def enrich(ep: Episode) -> Episode:
    """Add object facts and QA questions to the root factory's pick-and-place episode."""
    truth = ep.truth
    facts = []
    for f in truth.facts:
        lifted = f.holding is not None
        facts.append(
            f.model_copy(
                update={
                    "objects": {"can": ObjectFacts(lifted=lifted, on=None if lifted else "table")}
                }
            )
        )
    last = ep.num_frames - 1
    facts[last] = FrameFacts(gripper="open", objects={"can": ObjectFacts(inside="bin 2")})
    grasp = next(i for i, f in enumerate(facts) if f.holding)
    qa = [
        QAItem(
            question="Did the robot contact the can? If so, when?",
            answer=True,
            frame=grasp,
            template="did_contact",
            event="contact",
            object="can",
        ),
        QAItem(
            question="Did the robot pick up the can? If so, when?",
            answer=True,
            frame=grasp,
            template="did_pick_up",
            event="pick_up",
            object="can",
        ),
        QAItem(
            question="Did the robot drop the can? If so, when?",
            answer=False,
            template="did_drop",
            event="drop",
            object="can",
        ),
        QAItem(
            question="Did the robot place the can in bin 2? If so, when?",
            answer=True,
            frame=last,
            template="did_place",
            event="place",
            object="can",
        ),
    ]
    return ep.model_copy(update={"truth": truth.model_copy(update={"facts": facts, "qa": qa})})


@pytest.fixture
def make_dataset(make_episode):
    """Factory: a dataset directory with `n` enriched episodes of `frames` frames."""

    def _make(
        root: Path, n: int = 3, frames: int = 12, size: int = 32, wrist: bool = False
    ) -> Path:
        views = ["left", "wrist"] if wrist else ["left"]
        write_dataset_info(root, DatasetInfo(name=root.name, views=views))
        for i in range(n):
            ep = enrich(make_episode(n=frames, size=size, episode_id=f"ep{i}"))
            if wrist:
                pixels = ep.views["left"]
                ep = ep.model_copy(
                    update={
                        "view_names": views,
                        "views": {"left": pixels, "wrist": pixels[:, ::-1].copy()},
                    }
                )
            write_episode(root, ep)
        return root

    return _make


class _Handler(BaseHTTPRequestHandler):
    """An OpenAI-compatible chat endpoint answering like a frame-by-frame VLM.

    The reply depends only on the request (number of images, a hash of the text), so
    every run gets the same answers whatever order the calls come in.
    """

    def log_message(self, *args) -> None:  # keep test output quiet
        return

    def do_POST(self) -> None:  # noqa: N802 - http.server's naming
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        server: LoopbackServer = self.server.owner  # type: ignore[attr-defined]
        images = sum(
            1
            for m in body["messages"]
            if isinstance(m.get("content"), list)
            for p in m["content"]
            if p.get("type") == "image_url"
        )
        with server.lock:
            server.requests += 1
        if server.delay:
            import time

            time.sleep(server.delay)
        pct = min(100, 10 * images)
        text = _judge_or_qa_reply(body["messages"]) or (
            "Frame description: The gripper is open. The robot is not holding anything.\n"
            f"Task completion percentage: {pct}%\n"
            f"Subtask completion percentage: {pct}%\n[next-frame]"
        )
        reply = {
            "id": "x",
            "object": "chat.completion",
            "created": 0,
            "model": body.get("model", "m"),
            "choices": [
                {
                    "index": 0,
                    "finish_reason": "stop",
                    "message": {"role": "assistant", "content": text},
                }
            ],
            "usage": {
                "prompt_tokens": 100 + 85 * images,
                "completion_tokens": 20,
                "total_tokens": 120 + 85 * images,
            },
        }
        data = json.dumps(reply).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


def _text(messages: list[dict]) -> str:
    parts = []
    for m in messages:
        c = m.get("content")
        if isinstance(c, str):
            parts.append(c)
        else:
            parts += [p.get("text", "") for p in c if p.get("type") == "text"]
    return "\n".join(parts)


def _judge_or_qa_reply(messages: list[dict]) -> str | None:
    """Answers for the LLM judge and QA prompts, read off the prompt text like a model would."""
    text = _text(messages)
    if "Ground-truth simulator state" in text:
        desc = re.search(r'Frame description produced by a model:\n"(.*)"', text).group(1)
        truth = re.search(r"- The gripper is (open|closed)\.", text).group(1)
        said = re.search(r"[Tt]he gripper is (open|closed)", desc)
        if said is None:
            return "True statements: none\nFalse statements: none\nVerdict: inconclusive"
        ok = said.group(1) == truth
        claim = f"the gripper is {said.group(1)}"
        return (
            f"True statements: {claim if ok else 'none'}\n"
            f"False statements: {'none' if ok else claim}\nVerdict: {'true' if ok else 'false'}"
        )
    if "Frame descriptions:" in text:
        obj = re.search(r"Question: Did the robot \w+(?: up)? the (\w+)", text).group(1)
        for m in re.finditer(r"^Frame (\d+): (.*)$", text, re.M):
            if f"holding the {obj}" in m.group(2):
                return f"Answer: yes\nFrame: {m.group(1)}"
        return "Answer: no\nFrame: none"
    return None


class _QuietServer(ThreadingHTTPServer):
    daemon_threads = True

    def handle_error(self, request, client_address) -> None:
        return  # a client killed mid-request (the resume test does that) is not an error here


class LoopbackServer:
    def __init__(self, delay: float = 0.0) -> None:
        self.delay = delay
        self.requests = 0
        self.lock = threading.Lock()
        self.httpd = _QuietServer(("127.0.0.1", 0), _Handler)
        self.httpd.owner = self  # type: ignore[attr-defined]
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.httpd.server_address[1]}/v1"

    def __enter__(self) -> LoopbackServer:
        self.thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def loopback_vlm():
    """Factory: a running loopback OpenAI-compatible server (`.url`, `.requests`)."""
    servers: list[LoopbackServer] = []

    def _start(delay: float = 0.0) -> LoopbackServer:
        s = LoopbackServer(delay).__enter__()
        servers.append(s)
        return s

    yield _start
    for s in servers:
        s.__exit__(None, None, None)
