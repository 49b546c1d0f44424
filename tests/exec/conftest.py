"""One local Ray (2 CPUs) for every test here: starting Ray takes seconds, so it is shared.

The fake API key is in the environment only while Ray starts: its workers inherit it (as
they inherit a real user's), this test process does not keep it. So a request that
carries it proves a worker read its key from its own environment.
"""

from __future__ import annotations

import os

import pytest

WORKER_KEY = "sk-rayWORKER0123456789abcdefKEY"


@pytest.fixture(scope="session")
def ray_session():
    ray = pytest.importorskip("ray")
    if ray.is_initialized():  # someone else's session: its workers lack our key
        ray.shutdown()
    saved = os.environ.get("OPENAI_API_KEY")
    os.environ["OPENAI_API_KEY"] = WORKER_KEY
    os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        ray.init(num_cpus=2, include_dashboard=False, logging_level="WARNING")
    finally:
        if saved is None:
            os.environ.pop("OPENAI_API_KEY", None)
        else:
            os.environ["OPENAI_API_KEY"] = saved
    yield ray
    ray.shutdown()
