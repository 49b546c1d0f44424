"""robomimic / RoboCasa HDF5 demonstrations written with h5py."""

from __future__ import annotations

import numpy as np
import pytest

from rover.errors import InputError
from rover.io.source import load_episode, open_source

from .conftest import frames_for


def test_demos_are_episodes_with_camera_choice(tmp_path, make_robomimic):
    path = make_robomimic(tmp_path / "lift.hdf5", lengths=(11, 8))
    reader = open_source(path)  # guessed from the suffix
    assert reader.kind == "hdf5" and reader.episode_ids() == ["demo_0", "demo_1"]
    ep = reader.read("demo_1", frames=3, size=None)
    assert ep.view == "agentview" and ep.view_names == ["agentview", "robot0_eye_in_hand"]
    assert ep.task == "lift the cube" and ep.frame_indices == [0, 4, 7]
    assert np.array_equal(ep.frames(), frames_for(8, 48, seed=10)[[0, 4, 7]])
    hand = load_episode(f"hdf5:{path}?camera=robot0_eye_in_hand&episode=demo_0&flip=1")
    assert np.array_equal(hand.frames(), frames_for(11, 48, seed=1)[:, ::-1])


def test_state_only_file_says_how_to_render(tmp_path, make_robomimic):
    path = make_robomimic(tmp_path / "low_dim.hdf5", with_images=False)
    with pytest.raises(InputError) as err:
        open_source(f"hdf5:{path}").read("demo_0")
    msg = str(err.value)
    assert "only states" in msg and "rover generate --source-hdf5" in msg and str(path) in msg


def test_not_robomimic_and_not_hdf5(tmp_path):
    import h5py

    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.create_dataset("x", data=np.zeros(3))
    with pytest.raises(InputError, match="no 'data' group"):
        open_source(other)
    junk = tmp_path / "junk.hdf5"
    junk.write_bytes(b"not an hdf5 file at all")
    with pytest.raises(InputError, match="unreadable HDF5"):
        open_source(junk)
