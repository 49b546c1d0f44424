"""The paper preset's one table (App. B, Tables 4 and 5) and `rover generate --preset`."""

from __future__ import annotations

import pytest
from typer.testing import CliRunner

from rover.cli import app
from rover.errors import InputError
from rover.sim.generate import GenerateConfig, work_items
from rover.sim.kitchen.presets import (
    PAPER_GROUPS,
    PAPER_STATED_VIDEOS,
    paper_counts,
    paper_plan,
    paper_task_names,
    paper_videos,
)
from rover.sim.tasks import get_task, task_names


def test_table_5_counts_and_the_papers_stated_total():
    # 27 tasks in 9 groups (Table 4)
    assert len(PAPER_GROUPS) == 9 and len(paper_task_names()) == 27
    assert len(set(paper_task_names())) == 27
    # Table 5, per task: pick-and-place 7 levels x 3, doors/drawers 5 x 4, appliances
    # 3 x 6, knobs 5 x 4, thawing 5 x 4, pantry/vegetables/coffee 3 x 7, pre-soak 4 x 5
    per_group = {gid: len(g.tasks) * sum(g.counts) for gid, g in PAPER_GROUPS.items()}
    assert per_group == {
        "pick_and_place": 210,
        "doors_drawers": 80,
        "appliances": 54,
        "fixtures_knobs": 100,
        "microwave_thawing": 20,
        "restock_pantry": 21,
        "arrange_vegetables": 21,
        "prepare_coffee": 21,
        "presoak_pan": 20,
    }
    # the table adds up to 547; the paper's text says 543 (documented in presets.py)
    assert paper_videos() == sum(per_group.values()) == 547
    assert PAPER_STATED_VIDEOS == 543
    assert paper_counts("kitchen.TurnOffMicrowave") == (6, 6, 6)
    with pytest.raises(KeyError):
        paper_counts("kitchen.Nope")


def test_every_built_paper_task_matches_its_table_row():
    built = [t for t in paper_task_names() if t in task_names("kitchen")]
    assert "kitchen.CloseSingleDoor" in built and "kitchen.TurnOffMicrowave" in built
    for name in built:
        spec = get_task(name)
        group = PAPER_GROUPS[spec.group]
        assert name.removeprefix("kitchen.") in group.tasks, name
        assert len(spec.levels) == len(group.counts), name
        assert spec.frames == group.frames, name


def test_plan_names_missing_tasks_or_writes_the_available_ones():
    registered = task_names("all")
    assert all(t in registered for t in paper_task_names())  # all 27 are registered
    tasks, counts, _ = paper_plan(registered)
    assert len(tasks) == 27 and sum(map(sum, counts.values())) == 547
    without = [t for t in registered if t != "kitchen.MicrowaveThawing"]
    with pytest.raises(InputError) as err:
        paper_plan(without)
    assert "kitchen.MicrowaveThawing" in str(err.value) and "--available-only" in str(err.value)
    have = ["kitchen.OpenDrawer", "kitchen.TurnOffMicrowave"]
    tasks, counts, note = paper_plan(have, available_only=True)
    assert tasks == ["kitchen.OpenDrawer", "kitchen.TurnOffMicrowave"]
    assert counts == {"kitchen.OpenDrawer": [4] * 5, "kitchen.TurnOffMicrowave": [6] * 3}
    assert "38 of the 547 videos" in note and "2 of 27 tasks" in note
    everything, _, _ = paper_plan(paper_task_names())
    assert len(everything) == 27
    with pytest.raises(InputError):
        paper_plan([], available_only=True)


def test_level_counts_schedule_each_level_as_table_5_says():
    name = "kitchen.TurnOffMicrowave"
    items = work_items(GenerateConfig(tasks=[name], level_counts={name: [1, 3, 2]}))
    assert [(i.level, i.k) for i in items] == [(1, 0), (2, 0), (2, 1), (2, 2), (3, 0), (3, 1)]
    # a video's plan index is the one the uniform schedule gives it
    uniform = work_items(GenerateConfig(tasks=[name], per_level=3))
    by_id = {i.episode_id: i.index for i in uniform}
    assert all(by_id[i.episode_id] == i.index for i in items)
    with pytest.raises(InputError):
        work_items(GenerateConfig(tasks=[name], level_counts={name: [1, 1]}))


@pytest.mark.parametrize(
    ("args", "said"),
    [
        (["--preset", "paper", "--tasks", "Lift"], "--preset paper sets --tasks"),
        (["--preset", "paper", "--per-level", "2"], "--per-level"),
        (["--preset", "papers"], "--preset must be 'paper'"),
        (["--available-only"], "--available-only goes with --preset"),
    ],
)
def test_generate_preset_refuses_up_front(tmp_path, args, said):
    out = tmp_path / "ds"
    res = CliRunner().invoke(app, ["generate", *args, "--out", str(out)])
    assert res.exit_code != 0
    assert said in str(res.exception) + res.output
    assert not out.exists()  # refused before any work


class _Captured(Exception):
    pass


def test_preset_sets_tasks_counts_views_and_size(tmp_path, monkeypatch):
    import rover.sim.generate as gen

    seen = {}

    def fake_generate(cfg, out, **kwargs):
        seen["cfg"] = cfg
        raise _Captured

    monkeypatch.setattr(gen, "generate", fake_generate)
    out = tmp_path / "ds"
    res = CliRunner().invoke(
        app, ["generate", "--preset", "paper", "--available-only", "-o", str(out)]
    )
    assert isinstance(res.exception, _Captured), res.output
    cfg = seen["cfg"]
    built = [t for t in paper_task_names() if t in task_names("all")]
    assert cfg.tasks == built
    assert cfg.level_counts == {t: list(paper_counts(t)) for t in built}
    assert cfg.views == ["wrist", "left", "right"] and cfg.size == 256
    assert cfg.frames is None  # each task's own: 30 atomic, 60 composite
    assert len(work_items(cfg)) == paper_videos(built)
    # --views and --size still apply
    res = CliRunner().invoke(
        app,
        ["generate", "--preset", "paper", "--available-only", "--views", "wrist,left"]
        + ["--size", "128", "-o", str(tmp_path / "ds2")],
    )
    assert isinstance(res.exception, _Captured), res.output
    assert seen["cfg"].views == ["wrist", "left"] and seen["cfg"].size == 128
    # with all 27 tasks registered the preset needs no --available-only
    res = CliRunner().invoke(app, ["generate", "--preset", "paper", "-o", str(tmp_path / "ds3")])
    assert isinstance(res.exception, _Captured), res.output
    assert seen["cfg"].tasks == paper_task_names()
    assert len(work_items(seen["cfg"])) == 547
