"""The kitchen env in MuJoCo: seeded scenes applied to the model, facts of its parts,
an expert run, and frames that show the scene."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.sim


@pytest.fixture(scope="module")
def kitchen(sim_env):
    return sim_env("kitchen.TurnOnMicrowave")


def _layout_and_looks(sim) -> tuple:
    env, m = sim.env, sim.model
    return (
        m.body_pos[list(env.fixture_body_ids.values())].copy(),
        m.geom_matid[env.surface_geoms["counter"]].copy(),
        m.light_pos.copy(),
        m.cam_pos.copy(),
    )


def test_scene_follows_the_seed_and_is_applied_to_the_model(kitchen):
    from rover.sim.kitchen.fixtures import COUNTER_TOP

    s1 = kitchen.reset(11)
    look1, scene1 = _layout_and_looks(kitchen), kitchen.env.scene.to_json()
    kitchen.reset(12)
    look2, scene2 = _layout_and_looks(kitchen), kitchen.env.scene.to_json()
    assert scene1 != scene2
    assert not np.allclose(look1[0], look2[0])  # fixture layout
    assert not np.allclose(look1[2], look2[2])  # light jitter
    assert not np.allclose(look1[3], look2[3])  # camera jitter
    again = kitchen.reset(11)
    assert np.array_equal(again, s1) and kitchen.env.scene.to_json() == scene1
    for a, b in zip(look1, _layout_and_looks(kitchen), strict=True):
        assert np.array_equal(a, b)
    # the model shows what the record says
    env, m = kitchen.env, kitchen.model
    place = env.scene.layout["Microwave"]
    assert np.allclose(m.body_pos[env.fixture_body_id], [place.x, place.y, COUNTER_TOP])
    want = env.material_ids[("counter", env.scene.textures["counter"])]
    assert set(m.geom_matid[env.surface_geoms["counter"]]) == {want}


def test_parts_not_in_use_stay_put(kitchen):
    """Stored or distant fixtures must not be pushed by the floor or their own case."""
    env = kitchen.env
    for seed in (0, 1, 2):
        kitchen.reset(seed)
        hold = np.zeros(len(kitchen.action_low))
        for _ in range(15):
            kitchen.step(hold)
        for name in env.fixtures:
            for joint in env_joints(kitchen, name):
                q = float(kitchen.data.qpos[kitchen.model.joint(joint).qposadr[0]])
                assert abs(q) < 2e-3, f"seed {seed}: {joint} moved to {q:.4f}"


def env_joints(sim, fixture: str) -> list[str]:
    from rover.sim.kitchen.fixtures import FIXTURES

    pre = sim.env.fixtures[fixture].naming_prefix
    return [pre + j for j in FIXTURES[fixture].joints.values()]


def test_expert_presses_the_microwave_button_and_events_follow(kitchen):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    demo = run_expert(kitchen, 3)
    assert demo.success and len(demo.subtask_ends) == 2
    facts = facts_for_states(kitchen, demo.states[[0, demo.subtask_ends[1], -1]])
    assert facts[0].articulations["button"] == 0.0 and facts[-1].articulations["button"] == 1.0
    events = {e.name: e.frame for e in detect_events(kitchen.spec, facts)}
    assert events["press"] == 1 and events["turn_on"] == 1


def test_frames_show_the_scene(kitchen):
    from rover.sim.render import StateRenderer

    r = StateRenderer(kitchen.model, 48)
    try:
        a = r.render(kitchen.reset(21)[None], ["left"])["left"][0].astype(int)
        b = r.render(kitchen.reset(22)[None], ["left"])["left"][0].astype(int)
        a2 = r.render(kitchen.reset(21)[None], ["left"])["left"][0].astype(int)
    finally:
        r.close()
    assert np.array_equal(a, a2)
    assert np.abs(a - b).mean() > 10  # other textures, layout, light: a visibly other kitchen


def test_spout_reads_as_a_turned_part(sim_env):
    from rover.sim.articulation import articulation_facts

    sim = sim_env("kitchen.TurnSinkSpout")
    sim.reset(0)
    env = sim.env
    assert env.kind == "spout" and env.part == "sink spout"  # facts name it for what it is
    sim.data.qpos[env.joint_qpos_addr] = 0.5 * env.target
    sim.sim.forward()
    assert articulation_facts(sim)[0] == {"sink spout": 0.5}
    assert not sim.predicate("turned:sink spout")
    sim.data.qpos[env.joint_qpos_addr] = env.target
    sim.sim.forward()
    assert sim.predicate("turned:sink spout")
