"""`rover generate` end to end (tiny), resume after interruption, one-line errors,
and the bundled dataset."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest
from typer.testing import CliRunner

from rover.errors import InputError
from rover.io.dataset import episode_ids, load_dataset, read_episode
from rover.sim import bundled_dataset_path
from rover.sim.validate import validate_dataset


def test_bundled_dataset_loads_and_validates():
    root = bundled_dataset_path()
    eps = load_dataset(root)
    assert {e.extra["sim_task"] for e in eps} == {"Lift", "PickPlaceCan"}
    for e in eps:
        assert e.num_frames == 30 and set(e.view_names) == {"left", "wrist"}
        assert e.frames("left").shape == (30, 128, 128, 3)
        assert e.truth.facts is not None and e.truth.qa
    assert validate_dataset(eps) == []
    size = sum(p.stat().st_size for p in root.rglob("*") if p.is_file())
    assert size < 5 * 1024 * 1024


def test_unknown_task_is_one_line_error(tmp_path):
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    res = subprocess.run(
        [sys.executable, "-m", "rover.cli", "generate", "--tasks", "Nope", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        env=env,
    )
    assert res.returncode != 0
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "valid tasks:" in lines[0] and "Lift" in lines[0]


@pytest.mark.sim
@pytest.mark.slow
def test_generate_tiny_and_resume(tmp_path):
    pytest.importorskip("robosuite")
    from rover.cli import app

    out = tmp_path / "ds"
    args = [
        "generate",
        "--tasks",
        "Lift",
        "--per-level",
        "1",
        "--levels",
        "1,last",
        "--frames",
        "8",
        "--size",
        "64",
        "--views",
        "left,wrist",
        "--demos",
        "1",
        "--out",
        str(out),
    ]
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    ids = episode_ids(out)
    assert ids == ["Lift-L1-000", "Lift-L4-000"]
    eps = load_dataset(out)
    assert validate_dataset(eps) == []
    top = read_episode(out, "Lift-L4-000")
    assert top.frames("wrist").shape == (8, 64, 64, 3)
    assert top.truth.progress[0] == 0.0 and top.truth.progress[-1] >= 0.95
    low = read_episode(out, "Lift-L1-000", load_frames=False)
    assert low.truth.progress[-1] < top.truth.progress[-1]
    # interrupt: one episode lost, one left half-written; the rerun redoes just those
    kept = (out / "episodes" / "Lift-L1-000" / "episode.json").stat().st_mtime_ns
    before = top.truth.progress
    shutil.rmtree(out / "episodes" / "Lift-L4-000")
    (out / "episodes" / "Lift-L4-000.part").mkdir()
    res = CliRunner().invoke(app, args)
    assert res.exit_code == 0, res.output
    assert episode_ids(out) == ids
    assert (out / "episodes" / "Lift-L1-000" / "episode.json").stat().st_mtime_ns == kept
    assert read_episode(out, "Lift-L4-000", load_frames=False).truth.progress == before
    assert not (out / "episodes" / "Lift-L4-000.part").exists()


@pytest.mark.sim
def test_source_hdf5_demos_drive_generation(tmp_path, sim_env):
    """A robomimic-layout file with no rover metadata (as a user's file would be)."""
    from rover.sim.demos import DemoRecord, write_demos
    from rover.sim.experts import run_expert
    from rover.sim.generate import GenerateConfig, generate

    demo = run_expert(sim_env("Lift"), 5)
    src = tmp_path / "user.hdf5"
    write_demos(src, "Lift", {}, [DemoRecord("demo_0", demo.states, demo.actions)])
    cfg = GenerateConfig(
        tasks=["Lift"],
        per_level=1,
        levels=["last"],
        frames=4,
        views=["left"],
        size=32,
        source_hdf5=str(src),
    )
    assert generate(cfg, tmp_path / "ds") == ["Lift-L4-000"]
    ep = load_dataset(tmp_path / "ds")[0]
    assert ep.truth.progress[-1] >= 0.95 and validate_dataset([ep]) == []
    wrong = tmp_path / "door.hdf5"
    write_demos(wrong, "Door", {}, [DemoRecord("demo_0", demo.states, demo.actions)])
    cfg = cfg.model_copy(update={"source_hdf5": str(wrong)})
    with pytest.raises(InputError, match="demonstrations of 'Door'"):
        generate(cfg, tmp_path / "ds2")
