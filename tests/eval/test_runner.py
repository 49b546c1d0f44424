"""The runner end to end on tiny datasets, through the real CLI."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rover import cli
from rover.cli import app

runner = CliRunner()


def _eval(*args: str):
    """`rover eval ARGS`, on the oracle unless ARGS name a backend (eval has no default)."""
    backend = [] if "--backend" in args else ["--backend", "oracle"]
    return runner.invoke(app, ["eval", *args, *backend], catch_exceptions=False)


def _metrics(out: Path) -> dict:
    return json.loads((out / "metrics.json").read_text())


def test_oracle_run_end_to_end(tmp_path: Path, make_dataset) -> None:
    ds = make_dataset(tmp_path / "ds", n=3, frames=12)
    out = tmp_path / "run"
    res = _eval(
        "--dataset",
        str(ds),
        "--methods",
        "rover,gvl,temporal-concat,local-concat",
        "--backend",
        "oracle",
        "--out",
        str(out),
        "--concurrency",
        "4",
    )
    assert res.exit_code == 0, res.output
    metrics = _metrics(out)
    assert metrics["counts"]["traces"] == 12
    assert metrics["counts"]["failed"] == 0
    for r in metrics["per_trace"]:
        # the oracle answers from ground truth: near-perfect progress, reasoning and QA
        assert r["pearson"] > 0.95, r
        assert r["error_rate"] == 0.0
        assert r["qa_accuracy"] == 100.0  # a percentage
        assert r["calls"] > 0 and r["total_tokens"] > 0
    run = json.loads((out / "run.json").read_text())
    assert run["dataset"] == str(ds) and run["methods"][0] == "rover"
    assert {"rover", "python", "numpy"} <= set(run["versions"])
    assert (out / "summary.md").read_text().startswith("# rover eval summary")
    assert len(list((out / "traces").rglob("*.json"))) == 12
    assert len(list((out / "judgements").rglob("*.json"))) == 12
    assert "rover eval: mean" in res.output and "run directory" in res.output  # main table
    # traces are the only JSON files with the Trace shape (the report relies on it)
    trace_like = [
        p for p in out.rglob("*.json") if {"method", "frames"} <= set(json.loads(p.read_text()))
    ]
    assert all(p.parts[-3] == "traces" for p in trace_like)


def test_sweeps_make_one_variant_per_combination(tmp_path: Path, make_dataset) -> None:
    ds = make_dataset(tmp_path / "ds", n=2, frames=12, wrist=True)
    out = tmp_path / "run"
    res = _eval(
        "--dataset",
        str(ds),
        "--methods",
        "rover,gvl",
        "--frames",
        "6,12",
        "--window",
        "3,6",
        "--views",
        "left,wrist",
        "--out",
        str(out),
    )
    assert res.exit_code == 0, res.output
    m = _metrics(out)
    ids = {v["id"] for v in m["variants"]}
    # rover: 2 frames x 2 windows x 2 views; gvl (no window): 2 frames x 2 views
    assert len(ids) == 12
    assert "rover__b=oracle__f=6__w=6__v=wrist" in ids
    assert "gvl__b=oracle__f=12__w=na__v=left" in ids
    assert len({(v["label"], v["view"]) for v in m["variants"]}) == 12  # views: a column
    trace = json.loads(
        (out / "traces" / "ep0" / "rover__b=oracle__f=6__w=6__v=wrist.json").read_text()
    )
    assert trace["num_frames"] == 6 and trace["params"]["window"] == 6
    assert trace["view"] == "wrist"
    assert trace["frame_indices"] == [0, 2, 4, 7, 9, 11]  # Episode.subsample(6) of 12
    by_view = {a["group"] for a in m["aggregates"] if a["by"] == "view"}
    assert by_view == {"left", "wrist"}
    summary = (out / "summary.md").read_text()
    for title in (
        "App. I: by frames per video",
        "App. J: by camera view",
        "App. M: by sliding-window size",
    ):
        assert title in summary
    frames = {(r["variant"], r["n_frames"]) for r in m["per_trace"]}
    assert all(n == (6 if "__f=6__" in v else 12) for v, n in frames)


def test_failing_episode_is_recorded_and_the_run_goes_on(tmp_path: Path, make_dataset) -> None:
    ds = make_dataset(tmp_path / "ds", n=3, frames=8)
    video = ds / "episodes" / "ep1" / "left.mp4"
    good = video.read_bytes()
    video.write_bytes(b"\x00not an mp4" * 50)
    out = tmp_path / "run"
    res = _eval("--dataset", str(ds), "--methods", "temporal-concat", "--out", str(out))
    assert res.exit_code == 1, res.output  # a run with failed units is not a success
    m = _metrics(out)
    assert m["counts"] == {**m["counts"], "traces": 2, "failed": 1}
    errors = [json.loads(x) for x in (out / "errors.jsonl").read_text().splitlines()]
    assert len(errors) == 1 and errors[0]["episode_id"] == "ep1"
    assert "left.mp4" in errors[0]["error"]
    assert "ep1" in (out / "summary.md").read_text()
    # the video repaired, a resume does only the failed unit and clears its error
    video.write_bytes(good)
    res = _eval("--dataset", str(ds), "--methods", "temporal-concat", "--out", str(out), "--resume")
    assert res.exit_code == 0, res.output
    assert _metrics(out)["counts"]["failed"] == 0
    assert (out / "errors.jsonl").read_text() == ""


def test_llm_judge_and_answerer_over_http(tmp_path: Path, make_dataset, loopback_vlm) -> None:
    server = loopback_vlm()
    ds = make_dataset(tmp_path / "ds", n=2, frames=8)
    out = tmp_path / "run"
    judge = f"openai:judge-model@{server.url}"
    res = _eval(
        "--dataset",
        str(ds),
        "--methods",
        "temporal-concat",
        "--backend",
        "oracle",
        "--flip-prob",
        "0.3",
        "--judge",
        judge,
        "--answerer",
        judge,
        "--no-cache",
        "--out",
        str(out),
    )
    assert res.exit_code == 0, res.output
    from rover.episode import FrameFacts

    described = 0
    for eid in ("ep0", "ep1"):
        j = json.loads(
            (
                out / "judgements" / eid / "temporal-concat__b=oracle__f=all__w=na__v=default.json"
            ).read_text()
        )
        trace = json.loads(
            (
                out / "traces" / eid / "temporal-concat__b=oracle__f=all__w=na__v=default.json"
            ).read_text()
        )
        n = sum(bool(f["description"]) for f in trace["frames"])
        assert j["judge"] == judge and j["calls"] == n
        described += n
        ep = json.loads((out / "episodes" / f"{eid}.json").read_text())
        for v, f, facts in zip(j["verdicts"], trace["frames"], ep["truth"]["facts"], strict=True):
            if not f["description"]:
                assert v["verdict"] == "inconclusive"
                continue
            said = "closed" if "gripper is closed" in f["description"] else "open"
            expected = "true" if said == FrameFacts(**facts).gripper else "false"
            assert v["verdict"] == expected
    # one judge call per described frame, one QA call per question, nothing else
    assert server.requests == described + 2 * 4
    m = _metrics(out)
    assert all(r["qa_n"] == 4 for r in m["per_trace"])


def _main(monkeypatch, capsys, *args: str) -> tuple[int, str]:
    backend = [] if "--backend" in args else ["--backend", "oracle"]
    monkeypatch.setattr(sys, "argv", ["rover", "eval", *args, *backend])
    with pytest.raises(SystemExit) as exc:
        cli.main()
    return exc.value.code, capsys.readouterr().err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--dataset", "{tmp}/nope"], "no such directory"),
        (["--dataset", "{ds}", "--methods", "rover,bogus"], "unknown method 'bogus'"),
        (["--dataset", "{ds}", "--frames", "30,abc"], "--frames: 'abc' is not a whole number"),
        (["--dataset", "{ds}", "--frames", "0"], "--frames: 0 is below the minimum"),
        (["--dataset", "{ds}", "--window", "1"], "--window: 1 is below the minimum"),
        (["--dataset", "{ds}", "--views", "top"], "no view 'top'"),
        (["--dataset", "{ds}", "--backend", "nonsense:x"], "unknown VLM spec"),
        (["--dataset", "{ds}", "--judge", "oracle"], "cannot judge or answer questions"),
        (["--dataset", "{ds}", "--source", "{ds}"], "either --dataset or --source"),
        ([], "--dataset DIR or --source SPEC"),
        (["--dataset", "{ds}", "--out", "{ds}"], "not empty; add --resume"),
    ],
)
def test_bad_inputs_give_one_line_errors(
    tmp_path, make_dataset, monkeypatch, capsys, args, message
) -> None:
    ds = make_dataset(tmp_path / "ds", n=1, frames=4)
    args = [a.format(tmp=tmp_path, ds=ds) for a in args]
    if "--out" not in args:
        args += ["--out", str(tmp_path / "run")]
    code, err = _main(monkeypatch, capsys, *args)
    assert code != 0
    assert message in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err


def test_resume_with_other_options_is_refused(tmp_path, make_dataset, monkeypatch, capsys) -> None:
    ds = make_dataset(tmp_path / "ds", n=1, frames=4)
    out = tmp_path / "run"
    assert _eval("--dataset", str(ds), "--methods", "gvl", "--out", str(out)).exit_code == 0
    code, err = _main(
        monkeypatch,
        capsys,
        "--dataset",
        str(ds),
        "--methods",
        "rover",
        "--out",
        str(out),
        "--resume",
    )
    assert code != 0 and "this run was made with methods=['gvl']" in err


def test_command_line_secrets_are_scrubbed() -> None:
    from rover.eval.runconfig import scrub_argv

    argv = [
        "rover",
        "eval",
        "--api-key",
        "abc123secret",
        "--token=xyz",
        "--api-key-env",
        "MYKEY",
        "--backend",
        "openai:gpt-4o@https://user:pw@host/v1?key=s3cr3t",
        "sk-abcdefghijklmn",
    ]
    out = " ".join(scrub_argv(argv))
    for secret in ("abc123secret", "xyz", "pw@", "s3cr3t", "sk-abcdefghijklmn"):
        assert secret not in out
    assert "MYKEY" in out  # the name of a variable is not a secret


def test_resume_after_judge_failures_needs_no_video(tmp_path: Path, make_dataset) -> None:
    """Traces done, LLM judge down: a resume retries judging from saved ground truth alone."""
    ds = make_dataset(tmp_path / "ds", n=2, frames=6)
    out = tmp_path / "run"
    dead = "openai:judge@http://127.0.0.1:9/v1"  # nothing listens on the discard port
    args = [
        "--dataset",
        str(ds),
        "--methods",
        "gvl",
        "--judge",
        dead,
        "--answerer",
        "none",
        "--no-cache",
        "--max-retries",
        "0",
        "--timeout",
        "5",
        "--out",
        str(out),
    ]
    assert _eval(*args).exit_code == 1  # judge failures are failed units: not a success
    errors = [json.loads(x) for x in (out / "errors.jsonl").read_text().splitlines()]
    assert [e["stage"] for e in errors] == ["judge", "judge"]
    traces = {p: p.read_bytes() for p in (out / "traces").rglob("*.json")}
    for video in ds.rglob("*.mp4"):
        video.unlink()  # a resume with only judging left must not need pixels
    assert _eval(*args, "--resume").exit_code == 1
    errors = [json.loads(x) for x in (out / "errors.jsonl").read_text().splitlines()]
    assert [e["stage"] for e in errors] == ["judge", "judge"]  # not "load"
    assert {p: p.read_bytes() for p in (out / "traces").rglob("*.json")} == traces
    m = _metrics(out)
    assert m["counts"]["traces"] == 2
    assert all(
        r.get("error_rate") is None and r["stage_error"].startswith("judge: ")
        for r in m["per_trace"]
    )


def test_eval_without_a_backend_names_the_choices(monkeypatch, capsys, tmp_path: Path) -> None:
    """No silent default: neither a paid API nor the oracle runs unless chosen."""
    monkeypatch.delenv("ROVER_BACKEND", raising=False)
    monkeypatch.setenv("ROVER_CONFIG", str(tmp_path / "none.toml"))
    monkeypatch.setattr(sys, "argv", ["rover", "eval", "--dataset", "bundled", "--out", "x"])
    with pytest.raises(SystemExit) as exc:
        cli.main()
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "no VLM backend chosen" in err and "oracle" in err
    assert len(err.strip().splitlines()) == 1
    monkeypatch.setenv("ROVER_BACKEND", "nonsense:x")
    with pytest.raises(SystemExit):
        cli.main()
    assert "unknown VLM spec 'nonsense:x'" in capsys.readouterr().err


def test_a_bad_judge_spec_names_the_option(monkeypatch, capsys, make_dataset, tmp_path) -> None:
    ds = make_dataset(tmp_path / "ds", n=1, frames=4)
    args = ["--dataset", str(ds), "--judge", "bogus", "--out", str(tmp_path / "run")]
    code, err = _main(monkeypatch, capsys, *args)
    assert code == 2 and err.strip().startswith("error: --judge: unknown VLM spec 'bogus'")
