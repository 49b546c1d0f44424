"""ProgressReward on robosuite's Lift through robosuite's own GymWrapper, driven by the
scripted expert: with the live simulator oracle and with a loopback OpenAI server."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("robosuite")
pytest.importorskip("gymnasium")

STEPS, EVERY, SIZE = 200, 5, 64


@pytest.fixture(scope="module")
def lift():
    """A Lift SimEnv, the expert's actions for seed 0 (padded to 200 steps), a renderer."""
    from rover.sim.env import SimEnv
    from rover.sim.experts import run_expert
    from rover.sim.render import StateRenderer
    from rover.sim.tasks import get_task

    sim = SimEnv(get_task("Lift"))
    demo = run_expert(sim, seed=0)
    assert demo.success
    actions = list(demo.actions[:STEPS])
    actions += [demo.actions[-1]] * (STEPS - len(actions))  # hold the cube up
    renderer = StateRenderer(sim.model, SIZE)
    yield sim, actions, renderer
    renderer.close()


def seeded_gym(sim):
    """robosuite's GymWrapper whose reset is rover's seeded reset (same cube placement
    and open fingers as the expert's recording, so its actions replay exactly)."""
    from robosuite.wrappers.gym_wrapper import GymWrapper

    class SeededGym(GymWrapper):
        def reset(self, seed=None, options=None):
            sim.reset(0 if seed is None else seed)
            return self._flatten_obs(self.env._get_observations(force_update=True)), {}

    return SeededGym(sim.env)


def run_wrapped(env, actions):
    obs, info = env.reset(seed=0)
    infos = [info]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        infos.append({**info, "reward": reward})
    return infos


def frame_of(sim, renderer):
    return lambda env: renderer.render(sim.get_state()[None], ["left"])["left"][0]


def test_lift_with_live_oracle_rises_to_done(lift):
    from rover.stream import LiveSimOracle, ProgressReward

    sim, actions, renderer = lift
    oracle = LiveSimOracle(sim)
    env = ProgressReward(
        seeded_gym(sim),
        sim.spec.description,
        oracle,
        every=EVERY,
        reward_scale=1.0,
        frame=frame_of(sim, renderer),
        observe=oracle.observe,
    )
    infos = run_wrapped(env, actions)
    trace = env.trace()  # (no env.close(): it would close the module's shared robosuite env)
    pushed = [i for i in infos if i["progress_updated"]]
    assert len(pushed) == STEPS // EVERY + 1  # reset + every 10th step
    values = [i["progress"] for i in pushed]
    assert values[0] == 0 and values[-1] >= 95
    assert values == sorted(values)  # rises on the expert, never falls
    done = values.index(100.0)  # the expert lifts the cube at step 35 of its 56
    assert len(set(values[:done])) >= 5  # and rises in steps on the way, not in one jump
    assert all(v == 100 for v in values[done:]) and pushed[-1]["progress_complete"]
    # the change is reported as delta on the pushing step, 0 in between
    assert sum(i["progress_delta"] for i in infos) == pytest.approx(values[-1])
    # reward = robosuite's own sparse reward (0 or 1) + progress_delta / 100
    env_rewards = {round(i["reward"] - i["progress_delta"] / 100, 9) for i in infos[1:]}
    assert env_rewards <= {0.0, 1.0}
    assert pushed[-1]["progress_subtask"] == ["lift the cube"]
    # the trace is the stream's: frames indexed by env step, oracle-labelled
    assert trace.oracle and trace.frame_indices == list(range(0, STEPS + 1, EVERY))
    assert [c.name for c in oracle.episode.truth.subtasks] == ["grasp the cube", "lift the cube"]
    assert trace.progress()[-1] >= 95


def test_lift_through_loopback_openai_server(lift):
    """The same loop over real HTTP: a server that answers like a model would."""
    from rover.stream import ProgressReward
    from rover.vlm.config import BackendConfig
    from rover.vlm.loader import load_vlm
    from rover.vlm.testing import OpenAICompatServer

    sim, actions, renderer = lift
    actions = actions[:60]  # the wiring over HTTP; the 200-step run is the oracle's above
    seen: list[int] = []

    def answer(body):
        seen.append(sum(1 for m in body["messages"] for p in m["content"] if _is_image(p)))
        n = len(seen)
        if n == 1:
            return (
                "Frame description: a red cube on the table\n\n"
                "**Subtask completion percentage:** 0%"
            )
        return (
            f"**Frame description:** the gripper is nearer the cube\n"
            f"Subtask completion percentage: {min(5 * n, 100)}%\n[next-frame]"
        )

    with OpenAICompatServer() as server:
        server.answer = answer
        vlm = load_vlm(f"openai:test-model@{server.base_url}", BackendConfig(no_cache=True))
        env = ProgressReward(
            seeded_gym(sim), sim.spec.description, vlm, every=EVERY, frame=frame_of(sim, renderer)
        )
        infos = run_wrapped(env, actions)
        trace = env.trace()
        env.close()
    values = [i["progress"] for i in infos if i["progress_updated"]]
    assert len(values) == len(actions) // EVERY + 1
    assert values == sorted(values) and values[-1] == 65  # 5 points per call, 13 calls
    assert server.count == len(values) == trace.totals.calls  # one call per pushed frame
    assert seen[:3] == [1, 2, 3]  # first frame, then first + current, then the window of 3
    assert trace.backend == "openai" and not trace.oracle
    assert not any(np.isnan(values))


def _is_image(part) -> bool:
    return isinstance(part, dict) and part.get("type") == "image_url"
