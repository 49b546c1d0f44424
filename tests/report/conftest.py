"""A small real run directory in `rover eval`'s layout (docs/evaluation.md).

A dataset of episodes written with `rover.io.dataset`, hand-made traces for three methods
(noisier for the baselines), and judgements / QA answers from the evaluation's real rule
judge and rule answerer.
"""

from __future__ import annotations

import base64
import json
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from rover.episode import Episode, QAItem, StateType
from rover.eval.judge import rule_judge_trace
from rover.eval.qa import rule_answer_trace
from rover.eval.results import compute_metrics, write_results
from rover.eval.rundir import RunDir, write_json_atomic
from rover.eval.variants import expand_variants
from rover.io.dataset import DatasetInfo, write_dataset_info, write_episode
from rover.methods.trace import CallRecord, FrameRecord, LineNode, Trace
from rover.run.store import write_thumbs

INJECTION = "<script>document.title='pwned'</script>"


def _trace(
    ep: Episode,
    method: str,
    backend: str,
    rng: np.random.Generator,
    description_override: str | None = None,
) -> Trace:
    truth = ep.truth
    assert truth is not None and truth.facts is not None
    noise = {"rover": 4.0, "gvl": 15.0, "temporal-concat": 25.0}[method]
    frames = []
    for pos, ix in enumerate(ep.frame_indices):
        fact = truth.facts[pos]
        desc = (
            "The gripper is closed. The robot is holding the can. The can is lifted."
            if (fact.holding)
            else ("The gripper is open. The robot is not holding anything.")
        )
        if method == "temporal-concat" and pos in (2, 3):  # a perception error
            desc = "The gripper is closed. The robot is holding the can."
        if description_override and pos == 1:
            desc = description_override
        p = (
            0.0
            if pos == 0
            else float(np.clip(truth.progress[pos] * 100 + rng.normal(0, noise), 0, 100))
        )
        frames.append(
            FrameRecord(
                index=ix,
                position=pos,
                progress=p,
                description=desc,
                subtask_path=["grasp the can"] if pos < 5 else ["place it"],
                predicted=True,
            )
        )
    n_calls = {"rover": ep.num_frames + 3, "gvl": ep.num_frames, "temporal-concat": ep.num_frames}
    calls = [
        CallRecord(
            id=i,
            kind=f"{method}.step",
            prompt_tokens=800 * (1 + (method != "rover") * i // 3),
            completion_tokens=40,
        )
        for i in range(n_calls[method])
    ]
    tree = None
    if method == "rover":
        last = ep.frame_indices[-1]
        tree = LineNode(
            id=0,
            subtask=ep.task,
            depth=0,
            first_frame=0,
            last_frame=last,
            outcome="complete",
            planned_subtasks=["grasp the <b>can</b>", "place the can in the bin"],
            calls=3,
            children=[
                LineNode(
                    id=1,
                    subtask="grasp the <b>can</b>",
                    depth=1,
                    first_frame=0,
                    last_frame=4,
                    outcome="complete",
                    final_description="The robot is holding the can.",
                ),
                LineNode(
                    id=2,
                    subtask="place the can in the bin",
                    depth=1,
                    first_frame=4,
                    last_frame=last,
                    outcome="end_of_video",
                ),
            ],
        )
    t = Trace(
        method=method,
        params={"window": 3} if method == "rover" else {},
        backend=backend,
        model=backend,
        oracle=backend == "oracle",
        episode_id=ep.id,
        task=ep.task,
        view="left",
        num_frames=ep.num_frames,
        frame_indices=ep.frame_indices,
        frames=frames,
        tree=tree,
        calls=calls,
    )
    t.totals = t.compute_totals()
    return t


@pytest.fixture
def make_run(tmp_path: Path, make_episode):
    """Factory: a run directory in rover eval's layout: run.json, episodes/, frames/,
    traces, real rule-judge verdicts and QA answers, and metrics.json from the scorer."""

    def _make(
        backend: str = "oracle", name: str = "run", injection: bool = True, judged: bool = True
    ) -> Path:
        root = tmp_path / name
        dataset = root / "dataset"
        write_dataset_info(dataset, DatasetInfo(name="tiny", views=["left"]))
        rng = np.random.default_rng(0)
        episodes = []
        for k, (group, level) in enumerate(
            [("pick_and_place", 3), ("pick_and_place", 1), ("open_door", 2)]
        ):
            ep = make_episode(n=10, size=48, episode_id=f"ep{k}")
            assert ep.truth is not None
            if level < 3:  # a stall: progress stops rising and the states turn non-expert
                prog = [min(p, 0.5) for p in ep.truth.progress]
                states = [StateType.non_expert if p >= 0.5 else StateType.expert for p in prog]
                ep = ep.model_copy(
                    update={
                        "truth": ep.truth.model_copy(
                            update={"progress": prog, "state_type": states, "level": level}
                        )
                    }
                )
            qa = [
                QAItem(
                    question="Did the robot pick up the can? If so, when?",
                    answer=True,
                    frame=5,
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
            ]
            ep = ep.model_copy(
                update={"task_group": group, "truth": ep.truth.model_copy(update={"qa": qa})}
            )
            write_episode(dataset, ep)
            episodes.append(ep)
        run = root / "runs" / "r1"
        (run / "traces").mkdir(parents=True)
        variants = expand_variants(
            ["rover", "gvl", "temporal-concat"], [backend], [None], [None], [None]
        )
        config = {
            "schema_version": 1,
            "dataset": str(dataset),
            "sources": [],
            "episodes": [ep.id for ep in episodes],
            "episode_datasets": {ep.id: "tiny" for ep in episodes},
            "methods": [v.method for v in variants],
            "backends": [backend],
            "judge": "rule" if judged else "none",
            "answerer": "rule" if judged else "none",
            "variants": [v.model_dump(mode="json") for v in variants],
        }
        (run / "run.json").write_text(json.dumps(config))
        rundir = RunDir(run)
        for ep in episodes:  # what rover eval keeps of each episode: metadata and small frames
            write_json_atomic(rundir.episode_path(ep.id), ep.model_copy(update={"views": {}}))
            write_thumbs(run, ep.id, ep.view, ep.frames(), ep.frame_indices)
        for ep in episodes:
            for method in ("rover", "gvl", "temporal-concat"):
                override = INJECTION if injection and method == "rover" and ep.id == "ep0" else None
                trace = _trace(ep, method, backend, rng, override)
                vid = (
                    f"{method}__b={backend}__f=all__w={3 if method == 'rover' else 'na'}__v=default"
                )
                trace.save(run / "traces" / ep.id / f"{vid}.json")
                if judged:
                    for folder, result in (
                        ("judgements", rule_judge_trace(trace, ep, vid)),
                        ("qa", rule_answer_trace(trace, ep, vid)),
                    ):
                        (run / folder / ep.id).mkdir(parents=True, exist_ok=True)
                        (run / folder / ep.id / f"{vid}.json").write_text(result.model_dump_json())
        write_results(rundir, compute_metrics(rundir, config))
        return run

    return _make


# ---------------------------------------------------------------------------------------
# Headless Chromium over the DevTools protocol: load a page, collect every console error,
# uncaught exception and failed load, read the DOM, take a screenshot.

CHROMIUM = "/usr/bin/chromium"


@dataclass
class PageResult:
    title: str
    text: str  # document.body.innerText
    scripts: int  # <script> elements in the DOM
    errors: list[str]  # console errors, exceptions, failed loads
    broken_images: list[str]
    screenshot: bytes
    checks: dict = None  # type: ignore[assignment]  # name -> value of a JS expression


class _CDP:
    """A minimal DevTools client: numbered commands on one flattened browser session."""

    def __init__(self, ws) -> None:
        self.ws = ws
        self.next_id = 0
        self.events: list[dict] = []

    def send(
        self,
        method: str,
        params: dict | None = None,
        session: str | None = None,
        timeout: float = 30,
    ) -> dict:
        self.next_id += 1
        msg: dict = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        deadline = time.monotonic() + timeout
        while True:
            reply = json.loads(self.ws.recv(timeout=max(0.1, deadline - time.monotonic())))
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 30) -> None:
        deadline = time.monotonic() + timeout
        while not any(e.get("method") == method for e in self.events):
            self.events.append(
                json.loads(self.ws.recv(timeout=max(0.1, deadline - time.monotonic())))
            )

    def drain(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        while (left := deadline - time.monotonic()) > 0:
            try:
                self.events.append(json.loads(self.ws.recv(timeout=left)))
            except TimeoutError:
                return


def _errors(events: list[dict]) -> list[str]:
    out = []
    for e in events:
        m, p = e.get("method"), e.get("params", {})
        if m == "Runtime.exceptionThrown":
            out.append(f"exception: {p['exceptionDetails'].get('text')}")
        elif m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            out.append(f"console.{p['type']}: {p.get('args')}")
        elif m == "Log.entryAdded" and p["entry"].get("level") == "error":
            out.append(f"log: {p['entry'].get('text')} {p['entry'].get('url', '')}")
        elif m == "Network.loadingFailed":
            out.append(f"load failed: {p.get('errorText')}")
    return out


@pytest.fixture
def open_in_chromium(tmp_path: Path):
    """Load a local HTML file in headless Chromium and report what a reader would see."""

    def _open(page: Path, checks: dict[str, str] | None = None) -> PageResult:
        from websockets.sync.client import connect

        profile = tmp_path / f"chromium-profile-{len(list(tmp_path.glob('chromium-profile-*')))}"
        proc = subprocess.Popen(
            [
                CHROMIUM,
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--disable-quic",
                "--no-first-run",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                f"--user-data-dir={profile}",
                "--remote-debugging-port=0",
                "--window-size=1280,2000",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            port_file = profile / "DevToolsActivePort"
            deadline = time.monotonic() + 60
            while not (port_file.exists() and len(port_file.read_text().splitlines()) >= 2):
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError("chromium did not start its DevTools endpoint")
                time.sleep(0.1)
            port, path = port_file.read_text().splitlines()[:2]
            with connect(f"ws://127.0.0.1:{port}{path}", max_size=None, open_timeout=30) as ws:
                return _drive(_CDP(ws), page, checks or {})
        finally:
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()

    return _open


def _drive(cdp: _CDP, page: Path, checks: dict[str, str]) -> PageResult:
    target = cdp.send("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = cdp.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    for domain in ("Runtime", "Log", "Page", "Network"):
        cdp.send(f"{domain}.enable", session=session)
    cdp.send("Page.navigate", {"url": page.resolve().as_uri()}, session=session)
    cdp.wait_for("Page.loadEventFired")

    def js(expr: str):
        res = cdp.send(
            "Runtime.evaluate",
            {"expression": expr, "returnByValue": True, "awaitPromise": True},
            session=session,
        )
        return res["result"].get("value")

    # lazy images load only when scrolled to: make them eager, then wait for them all
    broken = js("""new Promise(done => {
        const imgs = Array.from(document.images);
        imgs.forEach(i => { i.loading = 'eager'; });
        Promise.all(imgs.map(i => i.decode().catch(() => null))).then(() =>
          done(imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src)));
    })""")
    cdp.drain(0.5)
    shot = cdp.send("Page.captureScreenshot", {"format": "png"}, session=session)
    results = {name: js(expr) for name, expr in checks.items()}  # after the screenshot
    return PageResult(
        title=js("document.title"),
        text=js("document.body.innerText"),
        scripts=js("document.querySelectorAll('script').length"),
        errors=_errors(cdp.events),
        broken_images=broken,
        screenshot=base64.b64decode(shot["data"]),
        checks=results,
    )
