"""Executor choice is checked before any work: one line, non-zero exit, nothing written."""

from __future__ import annotations

import sys

import pytest

from rover import cli
from rover.errors import InputError
from rover.exec import LocalExecutor, check_executor, make_executor
from rover.exec.generate_job import write_folder_atomic


def _main(monkeypatch, capsys, *args: str) -> tuple[int, str]:
    monkeypatch.setattr(sys, "argv", ["rover", *args])
    with pytest.raises(SystemExit) as exc:
        cli.main()
    return exc.value.code, capsys.readouterr().err


@pytest.mark.parametrize("command", ["generate", "eval"])
def test_missing_ray_names_the_extra_before_any_work(
    tmp_path, monkeypatch, capsys, command
) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # `import ray` now fails as if absent
    out = tmp_path / "out"
    extra = ["--dataset", "bundled", "--backend", "oracle"] if command == "eval" else []
    code, err = _main(monkeypatch, capsys, command, "--out", str(out), "--executor", "ray", *extra)
    assert code != 0
    assert "pip install 'rover-vlm[ray]'" in err, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--executor", "dask"], "--executor must be 'local' or 'ray'"),
        (["--ray-address", "auto"], "--ray-address applies to --executor ray only"),
    ],
)
def test_bad_executor_options_are_one_line(tmp_path, monkeypatch, capsys, args, message) -> None:
    out = tmp_path / "out"
    code, err = _main(monkeypatch, capsys, "generate", "--out", str(out), *args)
    assert code != 0 and message in err, err
    assert len(err.strip().splitlines()) == 1 and not out.exists()


def test_check_executor_refuses_an_empty_address() -> None:
    pytest.importorskip("ray")
    with pytest.raises(InputError, match="--ray-address is empty"):
        check_executor("ray", " ")


def _double(x: int, y: int = 0) -> int:
    return 2 * x + y


def test_local_executor_maps_argument_tuples_in_process_and_in_a_pool() -> None:
    with make_executor("local", workers=1) as ex:
        assert isinstance(ex, LocalExecutor) and ex.shares_files and not ex.remote
        assert list(ex.map_unordered(_double, [(1,), (2, 1)])) == [2, 5]
    with LocalExecutor(2) as ex:
        assert sorted(ex.map_unordered(_double, [(i,) for i in range(5)])) == [0, 2, 4, 6, 8]


def test_write_folder_atomic_replaces_a_leftover_part_and_refuses_paths(tmp_path) -> None:
    final = tmp_path / "episodes" / "e1"
    (tmp_path / "episodes" / "e1.part").mkdir(parents=True)
    (tmp_path / "episodes" / "e1.part" / "stale.mp4").write_bytes(b"old")
    write_folder_atomic(final, {"episode.json": b"{}", "left.mp4": b"\x00\x01"})
    assert sorted(p.name for p in final.iterdir()) == ["episode.json", "left.mp4"]
    assert not (tmp_path / "episodes" / "e1.part").exists()
    with pytest.raises(ValueError, match="not a plain name"):
        write_folder_atomic(tmp_path / "episodes" / "e2", {"../x": b""})
