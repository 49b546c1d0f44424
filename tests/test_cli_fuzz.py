"""The bad-input sweep: every command against hostile arguments, files, datasets and replies.

Each case runs the real CLI entry point (`rover.cli.main`) in-process and must end cleanly:
a non-zero exit with at most 3 lines on stderr that name the problem, or a usable result
(exit 0 with its output written); never a traceback, never a terminal escape sequence
from a model reply, never a secret in any stream. Hostile replies come from a loopback
OpenAI-compatible server.

Print the sweep's table (one row per case) with:

    python tests/test_cli_fuzz.py
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import sys
import traceback
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from rover.episode import Episode, FrameFacts, GroundTruth, StateType, Subtask
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode
from rover.io.video import write_video
from rover.vlm.testing import OpenAICompatServer, Reply

SECRET_KEY = "sk-fuzzSECRET0123456789abcdef"
URL_PASSWORD = "pw-fuzz-Secret-42"
BASIC = "Basic dXNlcjpwdy1mdXp6LVNlY3JldC00Mg=="
SECRETS = (SECRET_KEY, URL_PASSWORD, BASIC.split()[1])
TASK = "pick the can and place it in the bin"
GOOD_REPLY = "Frame description: the gripper moves.\nSubtask completion percentage: 50%"


@dataclass
class Case:
    """One bad input: the command line (with {placeholders}) and what a clean end names."""

    name: str
    argv: list[str]
    names: str  # a substring the error must contain (case-insensitive); "" for usable results
    ok: bool = False  # a usable result is expected (exit 0), e.g. hostile but parseable replies
    replies: list[Reply] = field(default_factory=list)  # scripted server replies, then `answer`
    answer: str | None = None  # what the loopback server says after the script
    out: str | None = None  # with ok: the file that must exist afterwards


@dataclass
class Outcome:
    rc: int
    stdout: str
    stderr: str
    crash: str = ""  # an exception that escaped main(), formatted


@dataclass
class World:
    """Files every case can point at, built once under `root`."""

    root: Path
    server: OpenAICompatServer

    def fmt(self, text: str) -> str:
        return text.format(t=self.root, url=self.server.base_url, pw=URL_PASSWORD)


# --- the world: real files, real videos, a real dataset, a real server ----------------


def _frames(n: int, size: int = 32) -> np.ndarray:
    out = np.zeros((n, size, size, 3), dtype=np.uint8)
    for t in range(n):
        out[t, :, :, 0] = 40 + 20 * t
        out[t, 8:16, (t * 3) % (size - 8) : (t * 3) % (size - 8) + 8] = 255
    return out


def _episode(episode_id: str = "ep0", n: int = 6, view: str = "left") -> Episode:
    half = n // 2
    facts = [FrameFacts(holding="can" if t >= half else None) for t in range(n)]
    return Episode(
        id=episode_id,
        task=TASK,
        task_group="pick_and_place",
        fps=10,
        frame_indices=list(range(n)),
        view_names=[view],
        truth=GroundTruth(
            progress=[t / (n - 1) for t in range(n)],
            state_type=[StateType.expert] * n,
            subtasks=[
                Subtask(name="grasp the can", start=0, end=half - 1, object="can"),
                Subtask(name="place the can", start=half, end=n - 1, object="can"),
            ],
            facts=facts,
            level=2,
        ),
        views={view: _frames(n)},
    )


def _hostile_dataset(root: Path, view: str) -> None:
    """A dataset whose episode.json names a view that is a path outside the dataset."""
    write_dataset_info(root, DatasetInfo(views=["left"]))
    folder = write_episode(root, _episode())
    meta = json.loads((folder / "episode.json").read_text())
    meta["view_names"] = [view]
    (folder / "episode.json").write_text(json.dumps(meta))


def build_world(root: Path, server: OpenAICompatServer) -> World:
    t = root
    (t / "empty_dir").mkdir()
    (t / "full_dir").mkdir()
    (t / "full_dir" / "notes.txt").write_text("somebody else's folder\n")
    (t / "a_file").write_text("just a file\n")
    (t / "empty.mp4").write_bytes(b"")
    (t / "corrupt.mp4").write_bytes(os.urandom(2048))
    (t / "text.mp4").write_text("this is not a video\n")
    write_video(t / "clip.mp4", _frames(6), fps=10)
    # outside the datasets: what a hostile dataset would try to read
    (t / "outside").mkdir()
    write_video(t / "outside" / "secret.mp4", _frames(6), fps=10)
    write_dataset_info(t / "ds", DatasetInfo(views=["left"]))
    write_episode(t / "ds", _episode())
    _hostile_dataset(t / "ds_dotdot", "../../../outside/secret")
    _hostile_dataset(t / "ds_abs", str(t / "outside" / "secret"))
    (t / "ds_nonutf8").mkdir()
    (t / "ds_nonutf8" / "dataset.json").write_bytes(b'{"name": "\xff\xfe"}')
    write_dataset_info(t / "ds_badep", DatasetInfo(views=["left"]))
    (t / "ds_badep" / "episodes" / "ep0").mkdir(parents=True)
    (t / "ds_badep" / "episodes" / "ep0" / "episode.json").write_bytes(b"\xff\xfe[1,")
    (t / "ds_empty").mkdir()
    write_dataset_info(t / "ds_empty", DatasetInfo(views=["left"]))
    (t / "nonutf8.jsonl").write_bytes(b'{"key": "\xff\xfe"}\n{"key": 1}\n')
    (t / "malformed.jsonl").write_text('{"v": 1}\n[1, 2]\n{"key": "a", "prompt": "b", "text": 3}\n')
    (t / "run_nonutf8").mkdir()
    (t / "run_nonutf8" / "run.json").write_bytes(b"\xff\xfe{")
    # what `rover generate --frames 8 --size 64` leaves behind, as far as resuming can tell
    gen = {"tasks": ["Lift"], "per_level": 1, "frames": 8, "size": 64, "seed": 0}
    write_dataset_info(t / "gen_small", DatasetInfo(views=["left", "wrist"], generator=gen))
    (t / "run_garbage").mkdir()
    (t / "run_garbage" / "run.json").write_text("[1, 2, 3]")
    return World(root=root, server=server)


# --- the cases ----------------------------------------------------------------------

R = ["reason", "{t}/clip.mp4", "--task", TASK, "--no-cache"]
ORACLE = ["--backend", "oracle"]
SRV = ["--backend", "openai:test-model@{url}", "--max-retries", "1", "--timeout", "5"]


def _reason_cases() -> list[Case]:
    out = ["--out", "{t}/out/trace.json"]
    c = [
        Case("reason: missing video", ["reason", "{t}/nope.mp4", *ORACLE], "nope.mp4"),
        Case("reason: empty file", ["reason", "{t}/empty.mp4", "--task", TASK, *ORACLE], "empty"),
        Case("reason: random bytes", ["reason", "{t}/corrupt.mp4", "--task", TASK, *ORACLE], ""),
        Case("reason: text as mp4", ["reason", "{t}/text.mp4", "--task", TASK, *ORACLE], ""),
        Case("reason: empty folder", ["reason", "{t}/empty_dir", "--task", TASK, *ORACLE], ""),
        Case("reason: bad spec prefix", ["reason", "bogus:thing", "--task", TASK, *ORACLE], ""),
        Case("reason: lerobot missing", ["reason", "lerobot:{t}/nope", *ORACLE], "nope"),
        Case("reason: rlds missing", ["reason", "rlds:{t}/nope", *ORACLE], "nope"),
        Case("reason: hdf5 missing", ["reason", "hdf5:{t}/nope.hdf5", *ORACLE], "nope"),
        Case("reason: dataset view ..", ["reason", "{t}/ds_dotdot", *ORACLE, *out], "name"),
        Case("reason: dataset view abs", ["reason", "{t}/ds_abs", *ORACLE, *out], "name"),
        Case("reason: dataset.json bytes", ["reason", "{t}/ds_nonutf8", *ORACLE], "dataset"),
        Case("reason: episode.json bytes", ["reason", "{t}/ds_badep", *ORACLE], "episode"),
        Case("reason: dataset no episodes", ["reason", "{t}/ds_empty", *ORACLE], "episode"),
    ]
    for value in ("0", "-1", "1000000", "abc", "2.5"):
        c.append(Case(f"reason: --frames {value}", [*R, *ORACLE, "--frames", value], "--frames"))
    for value in ("0", "-5", "100000", "abc"):
        c.append(Case(f"reason: --size {value}", [*R, *ORACLE, "--size", value], "--size"))
    for value in ("bogus", "", "ROVER", "[/]", "[link=http://x]m"):
        c.append(Case(f"reason: --method {value!r}", [*R, *ORACLE, "--method", value], "method"))
    for value in ("0", "-1", "abc"):
        c.append(Case(f"reason: --window {value}", [*R, *ORACLE, "--window", value], "window"))
    backends = [
        ("bogus", "unknown vlm spec"),
        ("", "spec"),
        ("openai:", "model"),
        ("openai:m@127.0.0.1:8000/v1", "scheme"),
        ("openai:m@localhost", "scheme"),
        ("openai:m@ftp://host/v1", "scheme"),
        ("openai:m@http://", "host"),
        ("openai:m@http://host:notaport/v1", "port"),
        ("gemini:m", "key"),
        ("hf:{t}/nope", "nope"),
        ("replay:{t}/nope.jsonl", "cassette"),
        ("replay:{t}/nonutf8.jsonl", "utf-8"),
        ("replay:{t}/malformed.jsonl", "malformed"),
        ("replay:{t}/a_file", "no recorded completions"),
        ("openai:m@http://u:{pw}@127.0.0.1:9/v1", "cannot connect"),
        ("openai:smile:@http://127.0.0.1:9/v1", "openai:smile:"),  # printed, not an emoji
        ("openai:[/]@http://127.0.0.1:9/v1", "openai:[/]"),
    ]
    for spec, names in backends:
        argv = [*R, "--backend", spec, "--max-retries", "1", *out]
        c.append(Case(f"reason: --backend {spec[:38]!r}", argv, names))
    opts = [
        (["--out", "{t}/empty_dir"], "directory"),
        (["--out", "{t}/a_file/trace.json"], "not a directory"),
        (["--view", "top"], "view"),
        (["--view", "../x"], "view"),
        (["--timeout", "0"], "--timeout"),
        (["--timeout", "-1"], "--timeout"),
        (["--concurrency", "0"], "--concurrency"),
        (["--max-retries", "-1"], "--max-retries"),
        (["--max-tokens", "0"], "--max-tokens"),
        (["--detail", "ultra"], "--detail"),
        (["--token-rule", "nope"], "--token-rule"),
        (["--record", "{t}/a_file/rec.jsonl"], "cassette"),
        (["--flip-prob", "2"], "--flip-prob"),
        (["--jitter", "-1"], "--jitter"),
        (["--bogus-flag"], "no such option"),
    ]
    on_ds = ["reason", "{t}/ds", *ORACLE]  # the oracle needs ground truth: a dataset episode
    for extra, names in opts:
        cache = [] if "--cache" in extra else ["--no-cache"]
        c.append(Case(f"reason: {' '.join(extra)[:40]}", [*on_ds, *cache, *extra], names))
    for target in ("{t}/a_file/c.sqlite", "{t}/a_file", "{t}/empty_dir"):
        argv = ["reason", "{t}/clip.mp4", "--task", TASK, *SRV, "--cache", target]
        c.append(Case(f"reason: --cache {target[4:]}", argv, "cache"))
    c.append(Case("reason: --task ''", ["reason", "{t}/clip.mp4", "--task", "", *ORACLE], "task"))
    c.append(Case("reason: no task", ["reason", "{t}/clip.mp4", *ORACLE], "task"))
    return c


def _reply_cases() -> list[Case]:
    """Hostile model replies: the run must finish (or fail in one line), the terminal intact."""
    out = ["--out", "{t}/replies/trace.json", "--frames", "4", "--method", "rover"]
    ok = dict(ok=True, out="{t}/replies/trace.json")
    hostile = [
        ("closing tag", "Frame description: [/] done [/bold]\nSubtask completion percentage: 40%"),
        ("link markup", "Frame description: [link=http://evil.example]click[/link]\n40%"),
        ("title escape", "Frame description: \x1b]0;pwned\x07\x1b[2J\x1b[31mred\nprogress: 40%"),
        ("emoji code", "Frame description: :smile: :cross_mark:\nprogress: 40%"),
        ("250 percent", "Frame description: done.\nSubtask completion percentage: 250%"),
        ("negative", "Frame description: odd.\nSubtask completion percentage: -40%"),
        ("no format", "I cannot help with that."),
        ("empty", ""),
        ("4 KB newlines", "\n" * 4096),
        ("4 KB brackets", "[" * 4096),
        ("unicode", "Frame description: 机器人 \u202e\u2066 moves\nprogress: 30%"),
        ("key echo", f"Frame description: key {SECRET_KEY} seen\nprogress: 30%"),
        ("basic echo", f"Frame description: Authorization: {BASIC}\nprogress 30%"),
        ("nul bytes", "Frame description: a\x00b\x00c\nSubtask completion percentage: 30%"),
        ("subtask markup", "Frame description: x\nThe robot needs to: [bold red]grab[/] it"),
    ]
    c = [Case(f"reply: {n}", [*R, *SRV, *out], "", answer=text, **ok) for n, text in hostile]
    bodies = [
        ("non-UTF-8 body", Reply(raw=b'{"choices": [{"message": {"content": "\xff"}}]}')),
        ("text/plain 200", Reply(raw=b"hello", content_type="text/plain")),
        ("JSON array", Reply(raw=b"[1, 2, 3]")),
        ("JSON null", Reply(raw=b"null")),
        ("truncated JSON", Reply(raw=b'{"choices": [{"mess')),
        ("content is int", Reply(raw=b'{"choices": [{"message": {"content": 7}}]}')),
    ]
    for name, reply in bodies:
        c.append(Case(f"reply: {name}", [*R, *SRV, *out], "malformed", replies=[reply] * 50))
    errors = [
        ("401 echoing Basic", Reply(status=401, text=f"bad header Authorization: {BASIC}"), "401"),
        ("401 echoing key", Reply(status=401, text=f"Incorrect API key {SECRET_KEY}"), "401"),
        ("404 model", Reply(status=404, text="model not found"), "404"),
        ("400 escape body", Reply(status=400, text="bad \x1b]0;pwned\x07 [/] request"), "400"),
        ("500 forever", Reply(status=500, text="boom"), "500"),
        ("429 forever", Reply(status=429, text="slow", headers={"retry-after": "0"}), "429"),
        ("long error body", Reply(status=403, text="x" * 290 + SECRET_KEY), "403"),
    ]
    for name, reply, names in errors:
        c.append(Case(f"reply: {name}", [*R, *SRV, *out], names, replies=[reply] * 50))
    return c


G = ["generate", "--tasks", "Lift", "--per-level", "1", "--frames", "4", "--size", "32"]


def _generate_cases() -> list[Case]:
    c = []
    bad = [
        (["--tasks", ""], "--tasks"),
        (["--tasks", "Nope"], "nope"),
        (["--per-level", "0"], "--per-level"),
        (["--levels", "99"], "--levels"),
        (["--levels", "abc"], "--levels"),
        (["--frames", "-1"], "--frames"),
        (["--frames", "1000000"], "--frames"),
        (["--size", "0"], "--size"),
        (["--size", "-5"], "--size"),
        (["--size", "100000"], "--size"),
        (["--views", "top"], "view"),
        (["--views", ""], "view"),
        (["--workers", "0"], "--workers"),
        (["--demos", "0"], "--demos"),
        (["--source-hdf5", "{t}/nope.hdf5"], "nope"),
        (["--seed", "abc"], "--seed"),
    ]
    for i, (extra, names) in enumerate(bad):  # each its own --out: a case never sees another's
        out = ["--out", f"{{t}}/gen{i}"]
        c.append(Case(f"generate: {' '.join(extra)[:40]}", [*G, *out, *extra], names))
    outs = [
        ("{t}/a_file", "not a directory"),
        ("{t}/a_file/ds", "not a directory"),
        ("{t}/full_dir", "non-empty"),
        ("{t}/ds", "did not make"),  # a dataset rover generate did not write
        ("{t}/gen_small", "other settings"),  # made by rover generate with other settings
    ]
    for target, names in outs:
        c.append(Case(f"generate: --out {target[4:]}", [*G, "--out", target], names))
    c.append(Case("generate: no --out", G, "--out"))
    return c


E = ["eval", "--methods", "rover", "--frames", "4", "--no-cache"]


def _eval_cases() -> list[Case]:
    out = ["--out", "{t}/evalrun"]
    ds = ["--dataset", "{t}/ds"]
    c = [
        Case("eval: --dataset missing", [*E, *out, "--dataset", "{t}/nope"], "nope"),
        Case("eval: --dataset a file", [*E, *out, "--dataset", "{t}/a_file"], "a_file"),
        Case("eval: --dataset empty dir", [*E, *out, "--dataset", "{t}/empty_dir"], "dataset"),
        Case("eval: dataset.json bytes", [*E, *out, "--dataset", "{t}/ds_nonutf8"], "dataset"),
        Case("eval: episode.json bytes", [*E, *out, "--dataset", "{t}/ds_badep"], "episode"),
        # an episode that cannot be read fails its units (the others run): non-zero, counted
        Case("eval: view ..", [*E, *out, "--dataset", "{t}/ds_dotdot"], "view name"),
        Case("eval: view absolute", [*E, *out, "--dataset", "{t}/ds_abs"], "view name"),
        Case("eval: no data", [*E, *out], "--dataset"),
        Case("eval: both data", [*E, *out, *ds, "--source", "{t}/clip.mp4"], "not both"),
        Case("eval: --source missing", [*E, *out, "--source", "{t}/nope.mp4"], "nope"),
        Case("eval: --source corrupt", [*E, *out, "--source", "{t}/corrupt.mp4"], ""),
        Case("eval: no --out", [*E, *ds], "--out"),
        Case("eval: 401 from server", [*E, *out, *ds, *SRV], "401", replies=[Reply(401)] * 50),
        Case(
            "eval: cache under a file",
            [*E[:-1], *out, *ds, *SRV[:2], "--cache", "{t}/a_file/c.sqlite"],
            "cache",
        ),
        # documented: --frames only subsamples; shorter episodes keep all their frames
        Case("eval: --frames 1000000", [*E, *out, *ds, "--frames", "1000000"], "", ok=True),
        Case("eval: --resume, no run yet", [*E, *out, *ds, "--resume"], "", ok=True),
    ]
    bad = [
        (["--methods", "bogus"], "bogus"),
        (["--methods", ""], "method"),
        (["--backend", "bogus"], "spec"),
        (["--backend", "openai:m@127.0.0.1:8000/v1"], "scheme"),
        (["--judge", "bogus"], "bogus"),
        (["--answerer", "bogus"], "bogus"),
        (["--frames", "0"], "--frames"),
        (["--frames", "abc"], "--frames"),
        (["--window", "1"], "--window"),
        (["--views", "top"], "view"),
        (["--views", "../x"], "view"),
        (["--concurrency", "0"], "--concurrency"),
        (["--calls-in-flight", "0"], "--calls-in-flight"),
        (["--limit", "0"], "--limit"),
        (["--limit", "-1"], "--limit"),
        (["--episodes", "0"], "--episodes"),
        (["--timeout", "0"], "--timeout"),
        (["--max-tokens", "0"], "--max-tokens"),
        (["--temperature", "-1"], "--temperature"),
        (["--flip-prob", "2"], "--flip-prob"),
        (["--methods", "clip-value"], "--model-path"),
        (["--out", "{t}/a_file"], "a_file"),
        (["--out", "{t}/a_file/run"], "a_file"),
        (["--out", "{t}/full_dir"], "full_dir"),
    ]
    for extra, names in bad:
        argv = [*E, *ds, *(out if "--out" not in extra else []), *extra]
        c.append(Case(f"eval: {' '.join(extra)[:40]}", argv, names))
    for i, case in enumerate(c):  # each case its own run directory
        case.argv = [a.replace("{t}/evalrun", f"{{t}}/evalrun{i}") for a in case.argv]
        if "--backend" not in case.argv:  # eval has no default backend: the oracle, offline
            case.argv += ["--backend", "oracle"]
    c.append(Case("eval: no backend chosen", [*E, *ds, *out], "no VLM backend chosen"))
    return c


def _report_cases() -> list[Case]:
    return [
        Case("report: missing run", ["report", "{t}/nope"], "nope"),
        Case("report: run is a file", ["report", "{t}/a_file"], "a_file"),
        Case("report: empty run dir", ["report", "{t}/empty_dir"], "traces"),
        Case("report: unrelated dir", ["report", "{t}/full_dir"], "traces"),
        Case("report: run.json bytes", ["report", "{t}/run_nonutf8"], "utf-8"),
        Case("report: run.json array", ["report", "{t}/run_garbage"], "run_garbage"),
        Case("report: a dataset", ["report", "{t}/ds"], "traces"),
        Case(
            "report: --out a file", ["report", "{t}/run_garbage", "--out", "{t}/a_file"], "a_file"
        ),
        Case(
            "report: --out under file", ["report", "{t}/empty_dir", "-o", "{t}/a_file/r"], "a_file"
        ),
        Case("report: --out unrelated", ["report", "{t}/empty_dir", "-o", "{t}/full_dir"], "full"),
        Case(
            "report: --max-episodes -1",
            ["report", "{t}/empty_dir", "--max-episodes", "-1"],
            "max-episodes",
        ),
        Case("report: --dataset missing", ["report", "{t}/empty_dir", "--dataset", "{t}/x"], ""),
        Case("report: markup in path", ["report", "{t}/[/]x[link=y]"], "x"),
        Case("report: no run", ["report"], "missing argument"),
    ]


def _demo_cases() -> list[Case]:
    return [
        Case("demo: --out a file", ["demo", "--out", "{t}/a_file"], "a_file"),
        Case("demo: --out under a file", ["demo", "--out", "{t}/a_file/demo"], "a_file"),
        Case("demo: --out unrelated", ["demo", "--out", "{t}/full_dir"], "full_dir"),
        Case("demo: --methods bogus", ["demo", "--out", "{t}/d1", "--methods", "bogus"], "bogus"),
        Case(
            "demo: --methods clip", ["demo", "--out", "{t}/d2", "--methods", "clip-value"], "clip"
        ),
        Case("demo: --methods ''", ["demo", "--out", "{t}/d3", "--methods", ","], "methods"),
        Case("demo: --limit abc", ["demo", "--out", "{t}/d4", "--limit", "abc"], "--limit"),
        Case("demo: unknown option", ["demo", "--bogus"], "no such option"),
    ]


def _root_cases() -> list[Case]:
    return [
        Case("rover: unknown command", ["frobnicate"], "no such command"),
        Case("rover: markup command", ["[/]"], "no such command"),
        Case("rover: escape in command", ["\x1b]0;pwned\x07"], "no such command"),
    ]


def all_cases() -> list[Case]:
    return [
        *_reason_cases(),
        *_reply_cases(),
        *_generate_cases(),
        *_eval_cases(),
        *_report_cases(),
        *_demo_cases(),
        *_root_cases(),
    ]


# --- running and judging -------------------------------------------------------------


def run_cli(argv: list[str]) -> Outcome:
    """`rover ARGV` in this process, as a user would run it: exit status and both streams."""
    from rover import cli

    out, err = io.StringIO(), io.StringIO()
    old_argv = sys.argv
    sys.argv = ["rover", *argv]
    rc, crash = 0, ""
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            cli.main()
    except SystemExit as exc:
        code = exc.code
        rc = code if isinstance(code, int) else (0 if code is None else 1)
    except BaseException as exc:  # anything escaping main() is what a user sees as a traceback
        rc, crash = 1, "".join(traceback.format_exception(exc))
    finally:
        sys.argv = old_argv
    return Outcome(rc, out.getvalue(), err.getvalue(), crash)


def judge(case: Case, got: Outcome, world: World) -> list[str]:
    """What is wrong with how `case` ended (empty: handled cleanly)."""
    problems = []
    streams = got.stdout + got.stderr
    lines = [ln for ln in got.stderr.splitlines() if ln.strip()]
    if got.crash or "Traceback (most recent call last)" in streams:
        first = (got.crash or streams).strip().splitlines()[-1]
        problems.append(f"traceback: {first[:100]}")
    if "Task exception was never retrieved" in streams:
        problems.append("unretrieved task exception")
    if "\x1b]" in streams or "\x1b[2J" in streams or "\x07" in streams:
        problems.append("terminal escape sequence reached the terminal")
    for secret in SECRETS:
        if secret in streams:
            problems.append("a secret was printed")
    if case.ok:
        if got.rc != 0:
            problems.append(f"expected a usable result, got rc {got.rc}: {got.stderr[-120:]}")
        elif case.out and not Path(world.fmt(case.out)).is_file():
            problems.append("exit 0 but no output written")
    else:
        if got.rc == 0:
            problems.append("exit 0 on bad input")
        if len(lines) > 3:
            problems.append(f"{len(lines)} lines on stderr")
        if case.names and case.names.lower() not in got.stderr.lower():
            problems.append(f"message does not name {case.names!r}: {got.stderr.strip()[:120]}")
    return problems


def run_case(case: Case, world: World) -> tuple[Outcome, list[str]]:
    server = world.server
    server.script(*case.replies)
    server.answer = lambda body: case.answer if case.answer is not None else GOOD_REPLY
    try:
        got = run_cli([world.fmt(a) for a in case.argv])
    finally:
        with server._lock:  # what one case scripted never leaks into the next
            server._script.clear()
    return got, judge(case, got, world)


@contextlib.contextmanager
def fuzz_world(root: Path) -> Iterator[World]:
    env = {
        "ROVER_CACHE_DIR": str(root / "cache"),
        "OPENAI_API_KEY": SECRET_KEY,
        "XDG_CONFIG_HOME": str(root / "config"),
        "COLUMNS": "200",
    }
    saved = {k: os.environ.get(k) for k in [*env, "GEMINI_API_KEY", "GOOGLE_API_KEY"]}
    os.environ.update(env)
    for k in ("GEMINI_API_KEY", "GOOGLE_API_KEY", "ROVER_BACKEND", "OPENAI_BASE_URL"):
        os.environ.pop(k, None)
    try:
        with OpenAICompatServer() as server:
            yield build_world(root, server)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


CASES = all_cases()


@pytest.fixture(scope="module")
def world(tmp_path_factory) -> Iterator[World]:
    with fuzz_world(tmp_path_factory.mktemp("fuzz")) as w:
        yield w


@pytest.mark.parametrize("case", CASES, ids=[c.name for c in CASES])
def test_bad_input_is_handled_cleanly(case: Case, world: World) -> None:
    got, problems = run_case(case, world)
    assert not problems, f"{case.name}: {problems}\n--- stderr ---\n{got.stderr}{got.crash}"


def test_the_sweep_is_broad() -> None:
    commands = {c.argv[0] for c in CASES}
    assert {"reason", "generate", "eval", "report", "demo"} <= commands
    assert len(CASES) >= 152


def test_a_hostile_dataset_never_opens_a_file_outside_it(world: World, monkeypatch) -> None:
    """Not even a decode attempt: the outside video is never opened."""
    import rover.io.dataset as dataset_module

    opened: list[Path] = []
    real = dataset_module.read_video

    def spy(path, *args, **kwargs):
        opened.append(Path(path))
        return real(path, *args, **kwargs)

    monkeypatch.setattr(dataset_module, "read_video", spy)
    for name in ("ds_dotdot", "ds_abs"):
        got = run_cli(["reason", str(world.root / name), "--backend", "oracle", "--no-cache"])
        assert got.rc != 0
    assert all("outside" not in str(p) for p in opened), opened


def _table(rows: list[tuple[Case, Outcome, list[str]]]) -> str:
    lines = [f"{'case':<44} {'rc':>3} {'lines':>5}  result", "-" * 100]
    for case, got, problems in rows:
        n = len([ln for ln in got.stderr.splitlines() if ln.strip()])
        said = [ln for ln in got.stderr.splitlines() if ln.strip()] or [""]
        verdict = "FAIL " + "; ".join(problems) if problems else ("ok   " + said[-1].strip())
        lines.append(f"{case.name[:44]:<44} {got.rc:>3} {n:>5}  {verdict[:120]}")
    failed = sum(1 for *_, p in rows if p)
    lines.append("-" * 100)
    lines.append(f"{len(rows)} cases, {len(rows) - failed} handled cleanly, {failed} not")
    return "\n".join(lines)


def main(select: Callable[[Case], bool] = lambda c: True) -> int:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp, fuzz_world(Path(tmp)) as w:
        rows = [(c, *run_case(c, w)) for c in CASES if select(c)]
    print(_table(rows))
    return 1 if any(p for *_, p in rows) else 0


if __name__ == "__main__":
    wanted = sys.argv[1:]
    sys.exit(main(lambda c: not wanted or any(w in c.name for w in wanted)))
