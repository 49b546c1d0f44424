"""LeRobot v2.1 and v3.0 datasets written by the factories, read back frame by frame."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rover.errors import InputError
from rover.io.source import load_episode, open_source, with_frame_number_truth

from .conftest import CAMERA, WRIST, frames_for


def _close(a: np.ndarray, b: np.ndarray, tol: float = 12.0) -> bool:
    return float(np.abs(a.astype(int) - b.astype(int)).mean()) < tol


def test_v2_h264_reads_every_episode_with_task_and_indices(tmp_path, make_lerobot_v2):
    root = make_lerobot_v2(tmp_path / "ds", lengths=(12, 9), cameras=(CAMERA, WRIST))
    reader = open_source(f"lerobot:{root}")
    assert reader.episode_ids() == ["episode_000000", "episode_000001"]
    ep = reader.read("episode_000001", frames=4, size=None)
    assert ep.task == "open the drawer"
    assert ep.frame_indices == [0, 3, 5, 8]
    assert ep.view_names == [CAMERA, WRIST] and ep.view == CAMERA
    assert ep.fps == 10 and ep.extra["total_frames"] == 9
    assert _close(ep.frames(), frames_for(9, 64, seed=10)[[0, 3, 5, 8]])
    assert ep.truth is None


def test_v2_camera_from_query_and_images_in_parquet(tmp_path, make_lerobot_v2):
    root = make_lerobot_v2(tmp_path / "ds", cameras=(CAMERA, WRIST))
    ep = load_episode(f"lerobot:{root}?camera={WRIST}&episode=episode_000000", frames=3)
    assert ep.view == WRIST
    assert _close(ep.frames(), frames_for(12, 64, seed=1)[[0, 6, 11]])

    img_root = make_lerobot_v2(tmp_path / "img", images_in_parquet=True)
    ep = open_source(f"lerobot:{img_root}").read("episode_000000", frames=5)
    # PNG is lossless: exact pixels
    assert np.array_equal(ep.frames(), frames_for(12, 64, seed=0)[[0, 3, 6, 8, 11]])


def test_v3_av1_episodes_found_by_timestamp(tmp_path, make_lerobot_v3):
    root = make_lerobot_v3(tmp_path / "v3", lengths=(12, 9, 7), codec="libsvtav1")
    reader = open_source(root)  # guessed from meta/info.json
    assert reader.kind == "lerobot" and len(reader) == 3
    for i, n in enumerate((12, 9, 7)):
        ep = reader.read(f"episode_{i:06d}", size=None)
        assert ep.num_frames == n and ep.frame_indices == list(range(n))
        assert ep.task == ("stack the blocks", "wipe the table")[i % 2]
        assert _close(ep.frames(), frames_for(n, 64, seed=i * 10), tol=15)
    truth = with_frame_number_truth(reader.read("episode_000002", frames=3)).truth
    assert truth.progress == [0.0, 0.5, 1.0] and truth.progress_source == "frame_number"


def test_v3_h264_task_falls_back_to_tasks_parquet(tmp_path, make_lerobot_v3):
    import pyarrow.parquet as pq

    root = make_lerobot_v3(tmp_path / "v3", codec="libx264")
    ep_file = root / "meta/episodes/chunk-000/file-000.parquet"
    pq.write_table(pq.read_table(ep_file).drop(["tasks"]), ep_file)
    ep = load_episode(f"lerobot:{root}?episode=1", frames=2)  # a bare index works too
    assert ep.id == "episode_000001" and ep.task == "wipe the table"


def test_missing_meta_and_bad_camera_are_one_line_errors(tmp_path, make_lerobot_v2):
    root = make_lerobot_v2(tmp_path / "ds")
    with pytest.raises(InputError, match="no camera 'nope'.*cameras: observation.images.top"):
        open_source(f"lerobot:{root}?camera=nope")
    (root / "meta" / "episodes.jsonl").unlink()
    with pytest.raises(InputError, match=r"episodes\.jsonl: missing"):
        open_source(f"lerobot:{root}")
    (root / "meta" / "info.json").write_text(json.dumps({"codebase_version": "v2.1"}))
    with pytest.raises(InputError, match=r"info\.json: missing or invalid field 'features'"):
        open_source(f"lerobot:{root}")
    (root / "meta" / "info.json").unlink()
    with pytest.raises(InputError, match=r"info\.json: missing"):
        open_source(f"lerobot:{root}")


def test_v3_episode_past_end_of_video_names_field(tmp_path, make_lerobot_v3):
    import pyarrow as pa
    import pyarrow.parquet as pq

    root = make_lerobot_v3(tmp_path / "v3", lengths=(5, 4), codec="libx264")
    ep_file = root / "meta/episodes/chunk-000/file-000.parquet"
    table = pq.read_table(ep_file)
    col = f"videos/{CAMERA}/from_timestamp"
    idx = table.schema.get_field_index(col)
    table = table.set_column(idx, col, pa.array([0.0, 3.0]))
    pq.write_table(table, ep_file)
    with pytest.raises(InputError, match="from_timestamp"):
        open_source(f"lerobot:{root}").read("episode_000001")
