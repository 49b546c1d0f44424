"""A worker keeps the state of at most `KEEP_TASKS` tasks (a 17-task run was OOM-killed)."""

from __future__ import annotations

import rover.sim.attempt as attempt
import rover.sim.generate as gen


class _Renderer:
    closed = 0

    def close(self) -> None:
        _Renderer.closed += 1


def test_a_worker_drops_the_tasks_it_has_moved_past(monkeypatch):
    for name in ("_SIMS", "_RENDERERS", "_CACHE"):
        monkeypatch.setattr(gen, name, {})
    monkeypatch.setattr(gen, "_RECENT", [])
    monkeypatch.setattr(attempt, "_MARKS", {})
    for task in ("A", "B", "C", "B", "D"):
        gen._evict_all_but_recent(task)
        gen._SIMS[task] = object()
        gen._RENDERERS[(task, 64)] = _Renderer()
        gen._CACHE[(task, 64, "demos")] = object()
        attempt._MARKS[task] = {}
    assert sorted(gen._SIMS) == ["B", "D"]  # C went when D came; B was used after C
    assert sorted(k[0] for k in gen._RENDERERS) == ["B", "D"]
    assert sorted(k[0] for k in gen._CACHE) == ["B", "D"]
    assert sorted(attempt._MARKS) == ["B", "D"]
    assert _Renderer.closed == 2  # A's and C's EGL contexts were released
