"""The oracle backend: answers from ground truth in each prompt kind's format."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rover.episode import FrameFacts, ObjectFacts
from rover.errors import BackendError, InputError
from rover.methods import get_method
from rover.methods.registry import NON_VLM_METHODS, method_names
from rover.vlm.config import BackendConfig
from rover.vlm.oracle import OracleBackend, describe
from rover.vlm.types import Prompt, PromptMeta

VLM_METHODS = [m for m in method_names() if m not in NON_VLM_METHODS]


@pytest.mark.parametrize("name", VLM_METHODS)
async def test_oracle_curves_track_truth(make_episode, name):
    ep = make_episode(20)
    trace = await get_method(name).run(ep, OracleBackend())
    truth = [100 * p for p in ep.truth.progress]
    r = np.corrcoef(trace.progress(), truth)[0, 1]
    assert r > 0.9, (name, trace.progress())
    assert trace.oracle and trace.backend == "oracle" and trace.model == "ground-truth"
    assert trace.totals.parse_failures == 0
    assert trace.totals.total_tokens > 0 and trace.calls[0].usage_source == "estimated"
    assert trace.progress()[-1] == pytest.approx(100, abs=1)


async def test_oracle_rover_follows_truth_subtasks(make_episode):
    ep = make_episode(20)
    trace = await get_method("rover").run(ep, OracleBackend())
    tree = trace.tree
    assert [c.subtask for c in tree.children] == [s.name for s in ep.truth.subtasks]
    assert tree.planned_subtasks == [s.name for s in ep.truth.subtasks]
    # the first subtask line ends (at 100%) at the truth subtask's last frame
    assert tree.children[0].last_position == ep.truth.subtasks[0].end
    assert tree.children[0].outcome == "complete"
    assert trace.calls[0].image_tokens == 258  # Gemini rule for a small frame
    assert "The robot is holding the can." in (trace.frames[12].description or "")


async def test_oracle_noise_is_seeded(make_episode):
    ep = make_episode(20)

    async def run(seed, jitter=5.0, flip=0.3):
        cfg = BackendConfig(seed=seed, jitter=jitter, flip_prob=flip)
        return await get_method("rover").run(ep, OracleBackend(cfg))

    a, b, c = await run(1), await run(1), await run(2)
    assert a.progress() == b.progress()
    assert [f.description for f in a.frames] == [f.description for f in b.frames]
    assert a.progress() != c.progress()
    clean = await run(0, 0.0, 0.0)
    flipped = sum(
        x.description != y.description for x, y in zip(a.frames, clean.frames, strict=True)
    )
    assert flipped > 0


async def test_oracle_refuses_episodes_without_truth(make_episode):
    ep = make_episode(6).model_copy(update={"truth": None})
    with pytest.raises(InputError, match="has no ground truth: use a real backend"):
        await get_method("rover").run(ep, OracleBackend())
    with pytest.raises(BackendError, match="bound"):
        await OracleBackend().complete(Prompt(messages=[], meta=PromptMeta(kind="rover.step")))


async def test_oracle_unknown_kind(make_episode):
    vlm = OracleBackend().bind(make_episode(4))
    with pytest.raises(BackendError, match="cannot answer prompts of kind"):
        await vlm.complete(Prompt(messages=[], meta=PromptMeta(kind="nope", positions=[0])))


def test_description_vocabulary():
    facts = FrameFacts(
        gripper="closed",
        contacts=["can"],
        holding="can",
        objects={"can": ObjectFacts(lifted=True), "cube": ObjectFacts(inside="bin 2")},
        articulations={"door": 0.4, "button": 1.0},
        pressed=["button"],
    )
    assert describe(facts) == (
        "The gripper is closed. The gripper is touching the can. The robot is holding the can. "
        "The can is lifted. The cube is in bin 2. The door is 40% open. The button is pressed."
    )
    flipped = describe(facts, flip_prob=1.0)
    assert "The gripper is open." in flipped and "not holding anything" in flipped
    assert "The door is 60% open." in flipped and "The button is not pressed." in flipped
    assert describe(FrameFacts(objects={"can": ObjectFacts(on="table")})).endswith(
        "The can is on the table."
    )


async def test_oracle_plans_from_the_task_not_from_what_the_attempt_reached():
    from rover.io.source import load_episode
    from rover.vlm.oracle import task_plan

    # an L1 attempt never gets past the first subtask; a model would still plan both
    bundled = Path(__file__).parents[2] / "src/rover/data/bundled/episodes"
    ep = load_episode(str(bundled / "PickPlaceCan-L1-000"), frames=8)
    assert [s.name for s in ep.truth.subtasks] == ["pick up the can"]
    assert task_plan(ep) == ["pick up the can", "place the can in bin 4"]
    trace = await get_method("rover").run(ep, OracleBackend())
    assert trace.tree.planned_subtasks == task_plan(ep)
    assert [c.subtask for c in trace.tree.children] == ["pick up the can"]
    # the first of two subtasks: full-task progress is half the subtask's
    assert trace.progress()[-1] == pytest.approx(100 * ep.truth.progress[-1], abs=1)
