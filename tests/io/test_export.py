"""`rover export --format lerobot`: the bundled benchmark as LeRobot v3.0, read back exactly."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from rover.cli import app
from rover.errors import InputError
from rover.io.source import open_source
from rover.sim import bundled_dataset_path

pq = pytest.importorskip("pyarrow.parquet")


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("export") / "rover_bundled"
    res = CliRunner().invoke(app, ["export", "bundled", "--format", "lerobot", "--out", str(out)])
    assert res.exit_code == 0, res.output
    assert "as LeRobot v3.0" in res.output
    return out


def test_round_trip_through_lerobot_reader_is_exact(exported):
    source = open_source(bundled_dataset_path(), size=None)
    views = source.read(source.episode_ids()[0]).view_names
    for view in views:
        back = open_source(f"lerobot:{exported}?camera={view}", size=None)  # short camera name
        assert len(back) == len(source)
        for original_id, exported_id in zip(source.episode_ids(), back.episode_ids(), strict=True):
            a, b = source.read(original_id), back.read(exported_id)
            assert np.array_equal(a.frames(view), b.frames()), (view, original_id)
            assert b.truth == a.truth and b.truth.progress_source == "simulation"
            assert b.frame_indices == a.frame_indices and b.task == a.task
            assert b.task_group == a.task_group
            assert b.extra["source_episode_id"] == original_id


def test_layout_follows_lerobot_v3(exported):
    info = json.loads((exported / "meta" / "info.json").read_text())
    assert info["codebase_version"] == "v3.0" and info["total_episodes"] == 12
    assert info["data_path"] == "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
    assert info["video_path"] == (
        "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
    )
    feats = info["features"]
    for key in ("timestamp", "frame_index", "episode_index", "index", "task_index"):
        assert feats[key]["shape"] == [1]
    assert feats["observation.images.left"]["dtype"] == "video"
    assert feats["observation.images.left"]["info"]["video.codec"] == "h264"
    for key in ("progress", "state_type", "subtask_index", "level"):
        assert key in feats
    data = pq.read_table(exported / "data" / "chunk-000" / "file-000.parquet").to_pylist()
    assert len(data) == info["total_frames"] == 12 * 30
    assert [r["index"] for r in data] == list(range(len(data)))
    episodes = pq.read_table(exported / "meta" / "episodes" / "chunk-000" / "file-000.parquet")
    rows = episodes.to_pylist()
    assert [r["dataset_from_index"] for r in rows] == [30 * i for i in range(12)]
    assert all(r["rover/qa"] and "question" in r["rover/qa"][0] for r in rows)
    assert all(r["rover/level"] is not None for r in rows)
    tasks = pq.read_table(exported / "meta" / "tasks.parquet")
    assert b"pandas" in tasks.schema.metadata  # pandas restores the task strings as index
    assert tasks.column("task_index").to_pylist() == [0, 1]


def test_export_refusals(exported, tmp_path):
    res = CliRunner().invoke(app, ["export", "bundled", "--out", str(exported)])
    assert isinstance(res.exception, InputError) and "not empty" in str(res.exception)
    res = CliRunner().invoke(app, ["export", "bundled", "--format", "rlds", "--out", "x"])
    assert "valid formats: lerobot" in str(res.exception)
    res = CliRunner().invoke(app, ["export", str(tmp_path / "nope"), "--out", str(tmp_path / "o")])
    assert "no such dataset" in str(res.exception)


def test_lerobot_itself_loads_the_export(exported):
    """Where the lerobot package is installed, its own loader reads the export."""
    lerobot_dataset = pytest.importorskip("lerobot.datasets.lerobot_dataset")
    meta = lerobot_dataset.LeRobotDatasetMetadata("rover/bundled", root=exported)
    assert meta.total_episodes == 12 and meta.total_frames == 360
    assert meta.video_keys == ["observation.images.left", "observation.images.wrist"]
    assert list(meta.tasks.index)[0] == "Pick up the red cube from the table and lift it."
    ds = lerobot_dataset.LeRobotDataset("rover/bundled", root=exported, download_videos=False)
    row = ds.hf_dataset[31]
    assert int(row["episode_index"]) == 1 and int(row["frame_index"]) == 1


def test_stats_json_holds_every_feature_and_matches_the_frames(exported):
    """meta/stats.json: what a LeRobot policy normalises with, recomputed from the export."""
    info = json.loads((exported / "meta" / "info.json").read_text())
    stats = json.loads((exported / "meta" / "stats.json").read_text())
    assert set(stats) == set(info["features"])
    data = pq.read_table(exported / "data" / "chunk-000" / "file-000.parquet").to_pydict()
    progress = np.asarray(data["progress"], dtype=float)
    assert stats["progress"]["count"] == [len(progress)]
    assert np.isclose(stats["progress"]["mean"][0], progress.mean())
    assert np.isclose(stats["progress"]["std"][0], progress.std())
    assert stats["progress"]["min"] == [progress.min()] and stats["progress"]["max"] == [1.0]
    back = open_source(f"lerobot:{exported}?camera=left", size=None)
    frames = np.concatenate([back.read(i).frames() for i in back.episode_ids()]) / 255.0
    left = stats["observation.images.left"]
    assert np.asarray(left["mean"]).shape == (3, 1, 1) and left["count"] == [len(frames)]
    assert np.allclose(np.asarray(left["mean"]).ravel(), frames.mean(axis=(0, 1, 2)))
    assert np.allclose(np.asarray(left["std"]).ravel(), frames.std(axis=(0, 1, 2)))
    rows = pq.read_table(exported / "meta" / "episodes" / "chunk-000" / "file-000.parquet")
    first = rows.to_pylist()[0]
    assert np.isclose(first["stats/progress/mean"][0], progress[:30].mean())
    assert np.asarray(first["stats/observation.images.left/mean"]).shape == (3, 1, 1)


def test_merged_stats_equal_the_stats_of_the_union():
    from rover.io.lerobot_stats import column_stats, merge_stats, sample_positions

    rng = np.random.default_rng(0)
    a, b = rng.normal(size=17), rng.normal(3.0, 2.0, size=40)
    merged = merge_stats([column_stats(a.tolist()), column_stats(b.tolist())])
    whole = column_stats(np.concatenate([a, b]).tolist())
    for key in ("min", "max", "mean", "std", "count"):
        assert np.allclose(merged[key], whole[key]), key
    assert column_stats([None, None]) is None
    assert sample_positions(30) == list(range(30))
    long = sample_positions(5000)
    assert long[0] == 0 and long[-1] == 4999 and 100 <= len(long) < 5000
