"""The local process pool: results in completion order, and a dead worker is an error."""

from __future__ import annotations

import os

import pytest

from rover.errors import RoverError
from rover.exec import LocalExecutor


def test_pool_runs_every_job_and_a_dead_worker_stops_the_run_instead_of_hanging() -> None:
    with LocalExecutor(2) as ex:
        assert sorted(ex.map_unordered(abs, [(-1,), (-2,), (-3,)])) == [1, 2, 3]
        # a worker that exits mid-job (as one killed for memory does) never sends its
        # result: `multiprocessing.Pool` waited for it forever
        with pytest.raises(RoverError, match="worker process died"):
            list(ex.map_unordered(os._exit, [(3,)]))


def test_one_worker_runs_in_process() -> None:
    with LocalExecutor(1) as ex:
        assert list(ex.map_unordered(divmod, [(7, 2)])) == [(3, 1)]
