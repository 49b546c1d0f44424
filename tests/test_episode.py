import pytest

from rover.episode import even_positions
from rover.errors import InputError
from rover.io.dataset import DatasetInfo, load_dataset, write_dataset_info, write_episode


def test_even_positions_keep_first_and_last():
    assert even_positions(10, 4) == [0, 3, 6, 9]
    assert even_positions(5, 10) == [0, 1, 2, 3, 4]
    assert even_positions(7, 1) == [0]
    with pytest.raises(InputError):
        even_positions(7, 0)


def test_subsample_remaps_truth_by_position(make_episode):
    ep = make_episode(n=10)
    sub = ep.subsample(4)
    assert sub.frame_indices == [0, 3, 6, 9]
    assert sub.views["left"].shape[0] == 4
    assert sub.truth.progress == [ep.truth.progress[i] for i in (0, 3, 6, 9)]
    # the grasp at position 5 first shows in the kept frame at position 6 -> new position 2
    assert sub.truth.events[0].frame == 2
    assert [(s.start, s.end) for s in sub.truth.subtasks] == [(0, 1), (2, 3)]


def test_dataset_round_trip(tmp_path, make_episode):
    ep = make_episode(n=6, size=32)
    write_dataset_info(tmp_path, DatasetInfo(name="t", views=["left"]))
    write_episode(tmp_path, ep)
    (loaded,) = load_dataset(tmp_path)
    assert loaded.id == ep.id and loaded.truth == ep.truth
    assert loaded.views["left"].shape == ep.views["left"].shape
    # lossy H.264, but close
    diff = abs(loaded.views["left"].astype(int) - ep.views["left"].astype(int)).mean()
    assert diff < 6


def test_missing_dataset_is_one_line_error(tmp_path):
    with pytest.raises(InputError, match="not a rover dataset"):
        load_dataset(tmp_path)


def test_resized_keeps_aspect_and_never_upscales(make_episode):
    ep = make_episode(n=4, size=32)
    assert ep.resized(16).views["left"].shape == (4, 16, 16, 3)
    assert ep.resized(64).views["left"].shape == (4, 32, 32, 3)
    assert ep.resized(None) is ep


def test_select_and_view_validation(make_episode):
    ep = make_episode(n=6)
    with pytest.raises(InputError):
        ep.select([])
    with pytest.raises(ValueError):
        ep.select([3, 1])
    with pytest.raises(InputError, match="no view 'top'"):
        ep.with_view("top")
    assert ep.subsample(None) is ep and ep.subsample(10) is ep


def test_metadata_round_trips_without_pixels(make_episode):
    from rover.episode import Episode

    ep = make_episode(n=5)
    again = Episode.model_validate_json(ep.model_dump_json())
    assert again.truth == ep.truth and again.frame_indices == ep.frame_indices
    assert again.views == {}


def test_inconsistent_episodes_are_rejected(make_episode):
    from pydantic import ValidationError

    ep = make_episode(n=5)
    with pytest.raises(ValidationError, match="strictly increasing"):
        ep.model_validate({**ep.model_dump(), "frame_indices": [0, 2, 2, 3, 4]})
    with pytest.raises(ValidationError, match="progress values"):
        ep.model_validate({**ep.model_dump(), "frame_indices": [0, 1, 2]})
