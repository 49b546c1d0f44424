"""A run SIGKILLed at random points and resumed ends exactly like an uninterrupted run,
and never asks the backend again for work that was already finished.

The backend is a real HTTP server on 127.0.0.1 speaking the OpenAI chat API (answers
depend only on the request, so every run gets the same ones) and counting requests.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from rover.eval.rundir import read_units_log

METHODS = "temporal-concat,local-concat"


def _cmd(ds: Path, out: Path, url: str, resume: bool) -> list[str]:
    cmd = [
        sys.executable,
        "-m",
        "rover.cli",
        "eval",
        "--dataset",
        str(ds),
        "--methods",
        METHODS,
        "--backend",
        f"openai:loop@{url}",
        "--no-cache",
        "--concurrency",
        "2",
        "--calls-in-flight",
        "2",
        "--out",
        str(out),
    ]
    return cmd + (["--resume"] if resume else [])


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("OPENAI_API_KEY", None)
    env["COLUMNS"] = "200"
    return env


def _traces(out: Path) -> dict[str, str]:
    return (
        {
            str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in (out / "traces").rglob("*.json")
        }
        if (out / "traces").exists()
        else {}
    )


def _comparable(metrics: dict) -> dict:
    """metrics.json without wall-clock fields."""
    rows = [{k: v for k, v in r.items() if k != "latency_s"} for r in metrics["per_trace"]]
    return {**metrics, "per_trace": rows}


def _calls(out: Path) -> int:
    paths = (out / "traces").rglob("*.json")
    return sum(json.loads(p.read_text())["totals"]["calls"] for p in paths)


@pytest.mark.slow
def test_sigkill_and_resume_five_times(tmp_path: Path, make_dataset, loopback_vlm) -> None:
    ds = make_dataset(tmp_path / "ds", n=5, frames=12)
    rng = np.random.default_rng(0)
    # one server for both runs: the backend spec (with its port) is part of variant ids
    server = loopback_vlm(delay=0.05)

    # reference: one uninterrupted run
    ref_out = tmp_path / "ref"
    subprocess.run(
        _cmd(ds, ref_out, server.url, False),
        env=_env(),
        check=True,
        capture_output=True,
        timeout=300,
    )
    assert server.requests == _calls(ref_out)  # every request ends up in a trace
    server.requests = 0

    out = tmp_path / "run"
    finished: dict[str, str] = {}
    kills = 0
    progress: list[int] = []
    for attempt in range(5):
        proc = subprocess.Popen(
            _cmd(ds, out, server.url, attempt > 0),
            env=_env(),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        # kill after a random amount of new progress, so kills land mid-run
        start_lines = len(read_units_log(out)) if out.exists() else 0
        # a full run logs 6 lines per unit (start/done of trace, judge, qa): 60 in all
        target = start_lines + int(rng.integers(1, max(2, (60 - start_lines) // 2 + 1)))
        deadline = time.time() + 120
        while proc.poll() is None and time.time() < deadline:
            if len(read_units_log(out)) >= target:
                time.sleep(float(rng.uniform(0.0, 0.3)))
                break
            time.sleep(0.02)
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            kills += 1
        proc.wait(timeout=30)
        now = _traces(out)
        # nothing finished before was ever rewritten
        assert all(now.get(k) == v for k, v in finished.items())
        finished = now
        progress.append(len(finished))
    assert kills >= 3, "the run finished before it could be interrupted"
    assert 0 < len(finished) < 10, progress  # kills landed mid-run, after some finished work

    done = subprocess.run(
        _cmd(ds, out, server.url, True), env=_env(), capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    final = _traces(out)
    assert len(final) == 10 and all(final[k] == v for k, v in finished.items())

    # same numbers as the uninterrupted run
    m_ref = json.loads((ref_out / "metrics.json").read_text())
    m = json.loads((out / "metrics.json").read_text())
    assert _comparable(m) == _comparable(m_ref)
    assert json.loads((out / "run.json").read_text())["resumed"] == 5

    # no finished unit was started again: per unit, no 'start' after its 'done'
    log = read_units_log(out)
    starts: dict[str, int] = {}
    for i, line in enumerate(log):
        if line["stage"] != "trace":
            continue
        key = line["unit"]
        if line["event"] == "start":
            starts[key] = starts.get(key, 0) + 1
            assert not any(
                x["unit"] == key and x["stage"] == "trace" and x["event"] == "done" for x in log[:i]
            ), f"{key} restarted after it finished"
    assert sum(1 for x in log if x["stage"] == "trace" and x["event"] == "done") == 10
    # backend requests: every finished trace's calls, plus at most one partial attempt per
    # interruption of a unit (an interrupted attempt makes at most a full attempt's calls)
    per_unit = {}
    for p in (out / "traces").rglob("*.json"):
        t = json.loads(p.read_text())
        per_unit[f"{t['episode_id']}/{p.stem}"] = t["totals"]["calls"]
    final_calls = sum(per_unit.values())
    wasted_max = sum((starts[u] - 1) * per_unit[u] for u in per_unit)
    assert final_calls == _calls(ref_out)
    assert final_calls <= server.requests <= final_calls + wasted_max
