"""`rover validate DATASET`: the audit table, a non-zero exit on failures, one-line errors."""

from __future__ import annotations

import json
import shutil

from typer.testing import CliRunner

from rover.cli import app


def _copy_bundled(tmp_path):
    from rover.sim import bundled_dataset_path

    dst = tmp_path / "ds"
    shutil.copytree(bundled_dataset_path(), dst)
    return dst


def test_validate_prints_one_row_per_task_and_fails_on_a_broken_event(tmp_path):
    ds = _copy_bundled(tmp_path)
    ok = CliRunner().invoke(app, ["validate", str(ds)])
    assert "Lift" in ok.output and "PickPlaceCan" in ok.output and "final progress" in ok.output
    # break one episode: claim a drop at the first frame, where nothing is held
    path = sorted((ds / "episodes").glob("Lift-L1-*/episode.json"))[0]
    ep = json.loads(path.read_text())
    ep["truth"]["events"].append({"name": "drop", "object": "cube", "frame": 0})
    path.write_text(json.dumps(ep))
    bad = CliRunner().invoke(app, ["validate", str(ds), "--all"])
    assert bad.exit_code == 1
    assert "event drop 'cube' at frame 0" in bad.output and "FAIL" in bad.output


def test_validate_a_folder_that_is_not_a_dataset(tmp_path):
    res = CliRunner().invoke(app, ["validate", str(tmp_path)])
    assert res.exit_code != 0
    assert "not a rover dataset directory" in str(res.exception or res.output)
