"""Kitchen composite PreSoakPan: spec, the pan and its moving region, the articulated switch,
the chained expert's grasp yaw and a whole demonstration."""

from __future__ import annotations

import numpy as np
import pytest

from rover.episode import Event, FrameFacts, ObjectFacts
from rover.sim.kitchen.objects import instances
from rover.sim.kitchen.pan import PAN_REGION, handle_length, site_positions
from rover.sim.milestones import level_problems


def pre_soak_pan():
    from rover.sim.tasks import get_task

    return get_task("kitchen.PreSoakPan")


def test_registered_in_the_kitchen_suite_and_built_by_composites():
    from rover.sim.tasks import task_names

    registered = pre_soak_pan()  # the registry first: composites alone imports circularly
    from rover.sim.kitchen.composites import pre_soak_pan as build

    assert "kitchen.PreSoakPan" in task_names("kitchen")
    assert registered == build()


BASIN_LENGTH = 0.34  # m: the sink basin's inner length (sink.xml walls at y = +-0.17)


def test_spec_has_table5_levels_app_n_subtasks_and_c3_questions():
    spec = pre_soak_pan()
    assert spec.frames == 60 and spec.group == "presoak_pan"
    assert [s.name for s in spec.subtasks] == [
        "pick up the pan",
        "place the pan in the sink",
        "pick up the sponge",
        "place the sponge in the pan",
        "grasp the sink handle",
        "turn the sink handle",
    ]
    assert [s.end_signal for s in spec.subtasks] == [
        "lifted:pan",
        "placed:pan",
        "lifted:sponge",
        "placed:sponge",
        "grasped:sink handle",
        "turned:sink handle",
    ]
    # Table 5 numbers the rows 1, 2, 2, 4: four levels
    assert [lv.name for lv in spec.levels] == [
        "Fail to pick up the pan",
        "Pick up the pan and place it in the sink",
        "Pick up the sponge and place it in the pan",
        "Turn the sink handle to turn on the sink",
    ]
    assert spec.milestones == ["place:pan", "place:sponge", "turn_finish:sink handle"]
    assert spec.levels[-1].completes and spec.levels[0].terminal_grip == "open"
    assert [q.text for q in spec.qa_templates] == [
        "Did the robot pick up the pan? If so, when?",
        "Did the robot drop the pan? If so, when?",
        "Did the robot place the pan in the sink? If so, when?",
        "Did the robot pick up the sponge? If so, when?",
        "Did the robot drop the sponge? If so, when?",
        "Did the robot place the sponge in the pan? If so, when?",
        "Did the robot contact the sink handle? If so, when?",
        "Did the robot turn on the sink? If so, when?",
    ]
    assert len(spec.paraphrases) == 3
    assert spec.env_kwargs["articulated"] is True
    # the pan is taken by its handle: reach and contact are measured there
    assert spec.subtasks[0].object_points == ["pan:handle", "pan:handle"]


def _f(pan=None, sponge=None, handle=0.0, held=None) -> FrameFacts:
    return FrameFacts(
        holding=held,
        objects={
            "pan": ObjectFacts(inside=pan if pan == "sink" else None, on=pan if pan else None),
            "sponge": ObjectFacts(
                inside=sponge if sponge == "pan" else None, on=None if sponge == "pan" else sponge
            ),
        },
        articulations={"sink handle": handle},
    )


def test_levels_are_components_every_earlier_one_achieved():
    spec = pre_soak_pan()
    ms = spec.milestones
    start = _f("counter", "counter")
    pan_in = [start, _f(None, "counter", held="pan"), _f("sink", "counter")]
    sponge_in = [*pan_in, _f("sink", None, held="sponge"), _f("sink", "pan")]
    turned = [*sponge_in, _f("sink", "pan", 0.5), _f("sink", "pan", 1.0)]
    assert level_problems(1, ms, [start, start], []) == []
    assert level_problems(1, ms, pan_in, [])  # shows the component it fails
    assert level_problems(2, ms, pan_in, []) == []
    assert level_problems(2, ms, sponge_in, [])
    assert level_problems(3, ms, sponge_in, []) == []
    on = [Event(name="turn_finish", object="sink handle", frame=len(turned) - 1)]
    assert level_problems(3, ms, turned, on)
    assert level_problems(4, ms, turned, on) == []


def test_pan_fits_the_basin_and_its_region_is_its_floor():
    for inst in instances("pan"):
        assert handle_length(inst) < BASIN_LENGTH - 0.07  # room to set it down
        r, _, h = inst.size
        floor = site_positions(inst)["inside"][2]
        assert PAN_REGION.holds(inst, np.array([0.02, -0.01, floor + 0.02]), floor)
        assert PAN_REGION.holds(inst, np.array([0.0, 0.0, 0.0]), floor + 0.03)  # let go above
        assert not PAN_REGION.holds(inst, np.array([0.0, 0.0, 0.1]), floor + 0.08)  # carried
        assert not PAN_REGION.holds(inst, np.array([r, 0.0, 0.0]), floor)  # on the rim
        assert not PAN_REGION.holds(inst, np.array([r + 0.05, 0.0, 0.0]), -h)  # beside it


@pytest.fixture(scope="module")
def presoak():
    pytest.importorskip("robosuite")
    from rover.sim.env import SimEnv

    return SimEnv(pre_soak_pan())


def _settle(sim, steps: int = 60) -> None:
    hold = np.zeros(len(sim.action_low))
    for _ in range(steps):
        sim.step(hold)


def _put(sim, role: str, xyz) -> None:
    env = sim.env
    a, b = env.role_qpos[role]
    q = sim.data.qpos.copy()
    q[a : a + 3] = xyz
    sim.data.qpos[:] = q
    dof = env.role_dof[role]
    sim.data.qvel[dof : dof + 6] = 0.0
    env.sim.forward()


@pytest.mark.sim
def test_items_start_at_rest_the_spout_aside_and_the_scene_is_recorded(presoak):
    env = presoak.env
    for seed in range(3):
        presoak.reset(seed)
        objs = env.scene.to_json()["objects"]
        assert [o["role"] for o in objs] == ["pan", "sponge"]
        assert env.object_place("pan") == ("on", "counter")
        assert env.object_place("sponge") == ("on", "counter")
        start = {r: presoak.point(r) for r in ("pan", "sponge")}
        _settle(presoak, 10)
        for r, p in start.items():
            assert np.linalg.norm(presoak.point(r) - p) < 0.005, (seed, r)
        spout = env.fixture.naming_prefix + "spout"
        assert presoak.data.qpos[env.sim.model.get_joint_qpos_addr(spout)] == pytest.approx(
            1.0, abs=0.02
        )


@pytest.mark.sim
def test_sponge_dropped_in_the_pan_rests_on_its_floor_wherever_the_pan_is(presoak):
    """The pan region moves with the pan, and the pan's floor carries the sponge (a
    compiler-made inertial frame once let it fall through)."""
    env = presoak.env
    presoak.reset(1)
    pan = presoak.point("pan")
    floor = presoak.point("goal:pan")
    _put(presoak, "sponge", [pan[0], pan[1], floor[2] + 0.05])
    _settle(presoak)
    assert env.object_place("sponge") == ("inside", "pan")
    assert env.object_bottom("sponge") > floor[2] - 0.004  # on the floor, not through it
    # the pan (sponge in it) moved 10 cm along the counter: still inside the pan
    moved = presoak.point("sponge") - pan
    _put(presoak, "pan", pan + [0.0, 0.1, 0.0])
    _put(presoak, "sponge", pan + [0.0, 0.1, 0.0] + moved)
    _settle(presoak, 20)
    assert env.object_place("sponge") == ("inside", "pan")
    _put(presoak, "sponge", pan + [-0.2, 0.0, 0.0])  # beside the pan on the counter
    _settle(presoak, 20)
    assert env.object_place("sponge") == ("on", "counter")


@pytest.mark.sim
def test_articulated_switch_makes_the_sink_handle_the_scenes_joint(presoak, sim_env):
    from rover.sim.facts import frame_facts

    env = presoak.env
    presoak.reset(0)
    assert env.part == "sink handle" and env.kind == "knob"
    assert frame_facts(presoak).articulations == {"sink handle": 0.0}
    assert not presoak.predicate("turned:sink handle")
    env.sim.data.qpos[env.joint_qpos_addr] = env.target  # the lever a quarter turn on
    env.sim.forward()
    assert frame_facts(presoak).articulations["sink handle"] == pytest.approx(1.0)
    assert presoak.predicate("turned:sink handle")
    assert not env._check_success()  # the pan and sponge are still on the counter
    # a composite that does not work its fixture (the cabinet of ArrangeVegetables)
    # has no articulation facts
    other = sim_env("kitchen.ArrangeVegetables")
    other.reset(0)
    assert other.env.part == "" and frame_facts(other).articulations == {}


@pytest.mark.sim
def test_chained_expert_soaks_the_pan_in_order(presoak):
    from rover.sim.experts import run_expert
    from rover.sim.facts import detect_events, facts_for_states

    # seed 1 once folded the arm lifting the sponge beside the arm's base (wrist joint 6
    # at its limit at the end, the faucet lever out of reach)
    demo = run_expert(presoak, 1)
    assert demo.success and len(demo.subtask_ends) == 6
    presoak.set_state(demo.states[-1])
    assert presoak.data.qpos[5] < 3.4  # joint 6 (limit 3.75) unfolded
    picks = np.linspace(0, len(demo.states) - 1, 60).round().astype(int)
    facts = facts_for_states(presoak, demo.states[picks], demo.states[np.maximum(picks - 1, 0)])
    assert facts[-1].objects["pan"].inside == "sink"
    assert facts[-1].objects["sponge"].inside == "pan"
    assert facts[-1].articulations["sink handle"] >= 0.9
    ev = {(e.name, e.object): e.frame for e in detect_events(presoak.spec, facts)}
    assert ev[("drop", "pan")] is None and ev[("drop", "sponge")] is None
    order = [
        ev[("pick_up", "pan")],
        ev[("place", "pan")],
        ev[("pick_up", "sponge")],
        ev[("place", "sponge")],
        ev[("contact", "sink handle")],
        ev[("turn_finish", "sink handle")],
    ]
    assert None not in order and order == sorted(order), order


@pytest.mark.sim
def test_sponge_grasp_turns_from_home_toward_the_wrist_centre_never_past_it(presoak):
    """Of the sponge's two symmetric grasp yaws the expert takes the one between the start
    yaw (0, where home leaves the hand) and the yaw that centres the last joint, or the
    nearest to that range: a grasp a half turn from home rolled the wrist over."""
    from rover.sim.kitchen.composite_experts import WRIST_START, base_turn, turned_pick
    from rover.sim.motions import grasp_yaw

    for seed in range(6):
        presoak.reset(seed)
        chosen: list[float] = []
        phases = turned_pick(presoak, "sponge", "goal:pan", np.pi, 0.0, None, chosen).build()
        taken = phases[0].yaw()
        assert chosen[0] == taken
        assert np.sin(taken - grasp_yaw(presoak, "sponge", np.pi)) == pytest.approx(0, abs=1e-9)
        want = base_turn(presoak, presoak.point("sponge")) + WRIST_START
        lo, hi = min(0.0, want), max(0.0, want)
        outside = max(lo - taken, taken - hi, 0.0)
        assert outside <= (np.pi - (hi - lo)) / 2 + 1e-9, (seed, taken, want)


@pytest.mark.sim
def test_lever_turn_is_retried_until_the_lever_is_turned(presoak):
    from rover.sim.kitchen.composite_experts import chained_pick_place
    from rover.sim.motions import Retry

    env = presoak.env
    presoak.reset(0)
    last = chained_pick_place(presoak)[-1]
    assert isinstance(last, Retry) and last.tries > 1
    assert not last.check()  # the lever untouched: another try
    fresh = last.build()
    assert fresh and fresh is not last.build()  # each try built anew
    env.sim.data.qpos[env.joint_qpos_addr] = env.target
    env.sim.forward()
    assert last.check()
