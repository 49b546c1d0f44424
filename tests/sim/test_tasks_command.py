"""`rover tasks`: every task listed, expert success only where measured (and marked stale)."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

import rover.sim.expert_record as record
from rover.cli import app
from rover.sim.tasks import get_task, task_names


@pytest.fixture
def no_record(tmp_path, monkeypatch):
    path = tmp_path / "expert_success.json"
    monkeypatch.setattr(record, "RECORD", path)
    return path


def _json(*args: str) -> list[dict]:
    res = CliRunner().invoke(app, ["tasks", "--json", *args])
    assert res.exit_code == 0, res.output
    return json.loads(res.output)


def test_lists_every_task_with_its_parts(no_record):
    rows = _json()
    assert [r["name"] for r in rows] == task_names("all")
    door = next(r for r in rows if r["name"] == "kitchen.CloseSingleDoor")
    spec = get_task("kitchen.CloseSingleDoor")
    assert door["suite"] == "kitchen" and door["group_title"] == "Open/close doors/drawers"
    assert door["subtasks"] == [s.name for s in spec.subtasks]
    assert [lv["name"] for lv in door["levels"]] == [lv.name for lv in spec.levels]
    assert door["frames"] == 30 and door["paper_task"] is True
    assert door["expert_success"] == {"measured": False}
    assert all(r["suite"] == "tabletop" for r in _json("--suite", "tabletop"))
    assert not any(r["paper_task"] for r in _json("--suite", "tabletop"))


def test_expert_success_is_the_recorded_measurement(no_record):
    spec = get_task("kitchen.TurnOffMicrowave")
    record.write_record(spec, 19, 20, 33.4)
    record.write_record(get_task("Lift"), 20, 20, 60.0)  # a second task keeps the first
    rows = {r["name"]: r for r in _json()}
    got = rows["kitchen.TurnOffMicrowave"]["expert_success"]
    assert got["successes"] == 19 and got["seeds"] == 20 and got["first_seed"] == 0
    assert got["rate"] == pytest.approx(0.95) and got["stale"] is False and got["date"]
    assert rows["Lift"]["expert_success"]["successes"] == 20
    assert rows["kitchen.OpenDrawer"]["expert_success"] == {"measured": False}
    table = CliRunner().invoke(app, ["tasks", "--suite", "kitchen"], env={"COLUMNS": "220"})
    assert table.exit_code == 0
    line = next(ln for ln in table.output.splitlines() if "TurnOffMicrowave" in ln)
    assert "19/20" in line
    assert "not measured" in next(ln for ln in table.output.splitlines() if "OpenDrawer" in ln)
    # a record made before the task changed is stale, not current
    data = json.loads(no_record.read_text())
    data["tasks"]["kitchen.TurnOffMicrowave"]["fingerprint"] = "000000000000"
    no_record.write_text(json.dumps(data))
    again = {r["name"]: r for r in _json()}
    assert again["kitchen.TurnOffMicrowave"]["expert_success"]["stale"] is True
    detail = CliRunner().invoke(app, ["tasks", "kitchen.TurnOffMicrowave"])
    assert "19/20 on seeds 0..19" in detail.output and "stale" in detail.output
    assert "3: Press the button and turn the microwave off" in detail.output


def test_bad_names_are_one_line_errors(no_record):
    for args in (
        ["--suite", "moon"],
        ["NoSuchTask"],
        ["--suite", "tabletop", "kitchen.OpenDrawer"],
    ):
        res = CliRunner().invoke(app, ["tasks", *args])
        assert res.exit_code != 0 and res.exception is not None
        assert "\n" not in str(res.exception)


def test_checked_in_record_names_real_tasks():
    """The record `rover tasks` reads holds only registered tasks with sane numbers."""
    for name, rec in record.read_records().items():
        get_task(name)
        assert 0 <= rec["successes"] <= rec["seeds"] and rec["seeds"] >= 1
