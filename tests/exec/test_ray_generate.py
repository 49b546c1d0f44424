"""`rover generate --executor ray` writes the local run's bytes, and resumes the same way."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from rover.cli import app

pytestmark = pytest.mark.sim
runner = CliRunner()
ARGS = (
    "--tasks", "Lift", "--per-level", "1", "--levels", "1,last", "--size", "32",
    "--views", "left", "--frames", "8", "--demos", "1", "--seed", "3",
)  # fmt: skip


def _generate(out: Path, *extra: str) -> str:
    res = runner.invoke(app, ["generate", "--out", str(out), *ARGS, *extra])
    assert res.exit_code == 0, res.output
    return res.output


def _files(root: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(root)): p.read_bytes()
        for p in sorted((root / "episodes").rglob("*"))
        if p.is_file()
    }


def test_ray_generate_is_byte_identical_to_local_and_resumes(tmp_path, ray_session) -> None:
    pytest.importorskip("robosuite")
    local, ray_out = tmp_path / "local", tmp_path / "ray"
    _generate(local)
    said = _generate(ray_out, "--executor", "ray")
    assert "wrote 2 episodes" in said
    want = _files(local)
    assert sorted(want) == [
        "episodes/Lift-L1-000/episode.json",
        "episodes/Lift-L1-000/left.mp4",
        "episodes/Lift-L4-000/episode.json",
        "episodes/Lift-L4-000/left.mp4",
    ]
    assert _files(ray_out) == want  # episode.json and the MP4s, byte for byte
    info = [json.loads((d / "dataset.json").read_text()) for d in (local, ray_out)]
    assert info[0]["generator"] == info[1]["generator"]  # tries per level included
    # resume: a finished episode is kept, one cut short (only its .part left) is redone
    (ray_out / "episodes" / "Lift-L4-000").rename(ray_out / "episodes" / "Lift-L4-000.part")
    kept = (ray_out / "episodes" / "Lift-L1-000" / "episode.json").stat().st_mtime_ns
    said = _generate(ray_out, "--executor", "ray")
    assert "wrote 1 episodes" in said
    assert _files(ray_out) == want and not (ray_out / "episodes" / "Lift-L4-000.part").exists()
    assert (ray_out / "episodes" / "Lift-L1-000" / "episode.json").stat().st_mtime_ns == kept
