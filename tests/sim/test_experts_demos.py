"""Demonstrations round-trip through the robomimic HDF5 layout and replay in the env."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pytest

from rover.errors import InputError
from rover.sim.demos import DemoRecord, read_demos, read_env_args, write_demos


def test_robomimic_layout_round_trip(tmp_path):
    path = tmp_path / "demos.hdf5"
    recs = [
        DemoRecord(f"demo_{i}", np.full((5, 4), i, float), np.zeros((5, 7)), ep_meta={"seed": i})
        for i in (0, 1, 10, 2)
    ]
    write_demos(path, "Lift", {"use_latch": False}, recs)
    with h5py.File(path) as f:
        env_args = json.loads(f["data"].attrs["env_args"])
        assert env_args["env_name"] == "Lift" and env_args["env_kwargs"] == {"use_latch": False}
        assert f["data/demo_0/states"].shape == (5, 4)
        assert f["data/demo_0"].attrs["num_samples"] == 5
    assert read_env_args(path)["env_name"] == "Lift"
    back = read_demos(path)
    assert [d.name for d in back] == ["demo_0", "demo_1", "demo_2", "demo_10"]  # numeric order
    assert back[3].ep_meta == {"seed": 10} and back[3].states[0, 0] == 10


def test_bad_files_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        read_demos(tmp_path / "missing.hdf5")
    (tmp_path / "junk.hdf5").write_text("not hdf5")
    with pytest.raises(InputError, match="not a readable HDF5"):
        read_demos(tmp_path / "junk.hdf5")


@pytest.mark.sim
def test_saved_expert_replays_to_success(tmp_path, sim_env):
    from rover.sim.experts import run_expert

    sim = sim_env("Lift")
    demo = run_expert(sim, 1)
    path = tmp_path / "lift.hdf5"
    write_demos(path, "Lift", {}, [DemoRecord("demo_0", demo.states, demo.actions)])
    rec = read_demos(path)[0]
    sim.reset(1)
    sim.set_state(rec.states[-1])
    assert sim.success()
    sim.set_state(rec.states[0])
    assert not sim.success()
