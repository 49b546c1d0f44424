"""The edges a new user hits on real robot data (issue 13), each pinned by a test."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from PIL import Image

from rover.episode import Episode, GroundTruth
from rover.errors import InputError
from rover.eval.episodes import EpisodeRef, load_for_variants, source_refs, variant_episode
from rover.eval.variants import Variant
from rover.io.source import load_episode, open_source, spec_with_options
from rover.vlm.oracle import OracleBackend

from .conftest import CAMERA, WRIST, frames_for


def _two_camera_folder(root):
    """A robot-log layout: two cameras by file-name prefix, irregular indices."""
    root.mkdir()
    wrist, external = [0, 3, 7, 12], [0, 2, 5, 9, 14]
    for k, i in enumerate(wrist):
        Image.fromarray(frames_for(4, 16, seed=1)[k]).save(root / f"frame_wrist_{i}.png")
    for k, i in enumerate(external):
        Image.fromarray(frames_for(5, 16, seed=2)[k]).save(root / f"frame_external_{i}.png")
    return wrist, external


def test_frame_folder_with_two_cameras_by_prefix(tmp_path):
    folder = tmp_path / "clip"
    wrist, external = _two_camera_folder(folder)
    ep = load_episode(folder)
    assert ep.view_names == ["external", "wrist"] and ep.view == "external"
    assert ep.frame_indices == external
    ep = load_episode(f"{folder}?camera=wrist")
    assert ep.view == "wrist" and ep.frame_indices == wrist
    assert np.array_equal(ep.frames(), frames_for(4, 16, seed=1))
    assert load_episode(folder, view="frame_wrist").frame_indices == wrist  # the prefix too
    with pytest.raises(InputError, match="no view 'top'; views found: external, wrist"):
        load_episode(folder, view="top")


def test_frame_folder_duplicate_number_within_one_camera_is_still_an_error(tmp_path):
    folder = tmp_path / "dup"
    folder.mkdir()
    Image.fromarray(frames_for(1, 16)[0]).save(folder / "f_1.png")
    Image.fromarray(frames_for(1, 16)[0]).save(folder / "f_01.png")
    with pytest.raises(InputError, match="frame number 1 also used"):
        load_episode(folder)


def test_libero_task_from_problem_info(tmp_path, make_robomimic):
    import h5py

    path = make_robomimic(tmp_path / "libero.hdf5", lengths=(6,), task="")
    with h5py.File(path, "a") as f:
        del f["data/demo_0"].attrs["ep_meta"]
        f["data"].attrs["problem_info"] = json.dumps(
            {
                "problem_name": "libero_tabletop_manipulation",
                "language_instruction": "open the top drawer",
            }
        )
    reader = open_source(f"hdf5:{path}")
    assert reader.task_of("demo_0") == "open the top drawer"
    assert reader.read("demo_0", frames=2).task == "open the top drawer"


def test_missing_task_is_refused_before_any_call_and_task_option_fills_it(tmp_path, make_robomimic):
    path = make_robomimic(tmp_path / "robomimic.hdf5", lengths=(6, 5), task="")
    with pytest.raises(InputError, match="carries no task description; pass --task"):
        source_refs([f"hdf5:{path}"], None, 0)
    spec = spec_with_options(f"hdf5:{path}", task="lift the cube, then hold it")
    refs = source_refs([spec], None, 0)
    assert len(refs) == 2
    reader = open_source(refs[0].origin)
    assert reader.read("demo_1", frames=2).task == "lift the cube, then hold it"


def test_rlds_version_folders_are_named_by_builder_and_never_collide(tmp_path, make_rlds):
    bridge = make_rlds(tmp_path / "bridge" / "0.1.0", shards=((5,),), name="bridge")
    fractal = make_rlds(tmp_path / "fractal" / "1.0.0", shards=((5,),), name="fractal")
    for root in (bridge, fractal):
        (root / "dataset_info.json").unlink()  # the name must then come from the folders
    refs = source_refs([f"rlds:{bridge}", f"rlds:{fractal}"], None, 0)
    assert {r.dataset for r in refs} == {"bridge", "fractal"}
    assert refs[0].id.startswith("bridge__")
    twin = tmp_path / "copy" / "bridge" / "0.1.0"
    shutil.copytree(bridge, twin)
    with pytest.raises(InputError, match="both dataset 'bridge'"):
        source_refs([f"rlds:{bridge}", f"rlds:{twin}"], None, 0)


def test_view_sweeps_work_on_lerobot_with_short_names(tmp_path, make_lerobot_v2):
    root = make_lerobot_v2(tmp_path / "ds", lengths=(6,), cameras=(CAMERA, WRIST))
    ref = EpisodeRef("episode_000000", "episode_000000", "ds", f"lerobot:{root}")
    variants = [Variant(id=f"gvl-{v}", method="gvl", backend="x", view=v) for v in ("top", "wrist")]
    meta, loaded = load_for_variants(ref, variants)
    for v, seed in (("top", 0), ("wrist", 1)):
        ep = variant_episode(loaded, meta.frame_indices, next(x for x in variants if x.view == v))
        diff = np.abs(ep.frames().astype(int) - frames_for(6, 64, seed=seed).astype(int))
        assert float(diff.mean()) < 12


def test_lerobot_camera_short_name(tmp_path, make_lerobot_v2):
    root = make_lerobot_v2(tmp_path / "ds", lengths=(5,), cameras=(CAMERA, WRIST))
    assert open_source(f"lerobot:{root}?camera=wrist").camera == WRIST
    with pytest.raises(InputError, match=r"no camera 'side'.*observation.images.top \(top\)"):
        open_source(f"lerobot:{root}?camera=side")


def test_oracle_refuses_frame_number_truth(tmp_path):
    ep = Episode(
        id="real",
        task="t",
        frame_indices=[0, 1],
        view_names=["rgb"],
        truth=GroundTruth(progress=[0.0, 1.0], progress_source="frame_number"),
    )
    with pytest.raises(InputError, match="frame_number progress only"):
        OracleBackend().bind(ep)
    with pytest.raises(InputError, match="has no ground truth"):
        OracleBackend().bind(ep.model_copy(update={"truth": None}))
    sim = ep.model_copy(update={"truth": GroundTruth(progress=[0.0, 1.0])})
    assert OracleBackend().bind(sim).episode is sim
