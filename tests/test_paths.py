"""A dataset cannot make rover open a file outside it; outputs are checked before work."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

from rover.episode import Episode, GroundTruth
from rover.errors import InputError
from rover.io.dataset import DatasetInfo, read_episode, write_dataset_info, write_episode
from rover.io.video import write_video
from rover.paths import check_name, check_output_dir, check_output_file, inside


def _episode(episode_id: str = "ep0", view: str = "left") -> Episode:
    n = 3
    return Episode(
        id=episode_id,
        task="t",
        frame_indices=list(range(n)),
        view_names=[view],
        truth=GroundTruth(progress=[0.0, 0.5, 1.0]),
        views={view: np.zeros((n, 16, 16, 3), dtype=np.uint8)},
    )


def _dataset(root):
    write_dataset_info(root, DatasetInfo(views=["left"]))
    return write_episode(root, _episode())


@pytest.mark.parametrize("bad", ["../x", "/etc/passwd", "a/b", "a\\b", "..", ".", "", "a\x00b"])
def test_names_that_are_paths_are_refused(bad):
    with pytest.raises(InputError, match="name"):
        check_name(bad, "view name")


def test_ordinary_names_pass():
    for ok in ("left", "observation.images.top", "Lift-L1-000", "episode_000001", "a b"):
        assert check_name(ok, "name") == ok


@pytest.mark.parametrize("view", ["../../outside/secret", "{outside}/secret", "sub/left"])
def test_a_view_name_in_episode_json_cannot_point_outside(tmp_path, view):
    outside = tmp_path / "outside"
    outside.mkdir()
    write_video(outside / "secret.mp4", np.zeros((3, 16, 16, 3), dtype=np.uint8))
    folder = _dataset(tmp_path / "ds")
    meta = json.loads((folder / "episode.json").read_text())
    meta["view_names"] = [view.format(outside=outside)]
    (folder / "episode.json").write_text(json.dumps(meta))
    with pytest.raises(InputError, match="not a plain name"):
        read_episode(tmp_path / "ds", "ep0")


def test_an_episode_id_cannot_climb_out(tmp_path):
    _dataset(tmp_path / "ds")
    with pytest.raises(InputError, match="not a plain name"):
        read_episode(tmp_path / "ds", "../../ds/episodes/ep0")
    folder = tmp_path / "ds" / "episodes" / "ep0"
    meta = json.loads((folder / "episode.json").read_text())
    meta["id"] = "../evil"
    (folder / "episode.json").write_text(json.dumps(meta))
    with pytest.raises(InputError, match="episode id"):
        read_episode(tmp_path / "ds", "ep0")


def test_a_symlinked_video_that_leaves_the_dataset_is_refused(tmp_path):
    outside = tmp_path / "outside.mp4"
    write_video(outside, np.zeros((3, 16, 16, 3), dtype=np.uint8))
    folder = _dataset(tmp_path / "ds")
    (folder / "left.mp4").unlink()
    os.symlink(outside, folder / "left.mp4")
    with pytest.raises(InputError, match="outside"):
        read_episode(tmp_path / "ds", "ep0")
    assert read_episode(tmp_path / "ds", "ep0", load_frames=False).id == "ep0"


def test_writing_an_episode_with_a_path_for_a_name_is_refused(tmp_path):
    with pytest.raises(InputError):
        write_episode(tmp_path / "ds", _episode(episode_id="../escape"))
    with pytest.raises(InputError):
        write_episode(tmp_path / "ds", _episode(view="../left"))
    assert not (tmp_path / "escape").exists()


def test_inside_allows_the_root_itself_and_below(tmp_path):
    assert inside(tmp_path, "a", "b.mp4") == (tmp_path / "a" / "b.mp4").resolve()
    with pytest.raises(InputError):
        inside(tmp_path / "a", "..", "b")


def test_output_checks(tmp_path):
    (tmp_path / "file").write_text("x")
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x.txt").write_text("x")
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "dataset.json").write_text("{}")
    assert check_output_file(tmp_path / "new" / "trace.json").name == "trace.json"
    for bad, match in [(tmp_path, "directory"), (tmp_path / "file" / "t.json", "not a dir")]:
        with pytest.raises(InputError, match=match):
            check_output_file(bad)
    assert check_output_dir(tmp_path / "new") == tmp_path / "new"
    assert check_output_dir(tmp_path / "mine", marker="dataset.json")
    with pytest.raises(InputError, match="non-empty"):
        check_output_dir(tmp_path / "full", marker="dataset.json")
    with pytest.raises(InputError, match="not a directory"):
        check_output_dir(tmp_path / "file")
    with pytest.raises(InputError, match="not a directory"):
        check_output_dir(tmp_path / "file" / "sub")
