"""Level milestones and the dataset audit on hand-written facts (no MuJoCo needed)."""

from __future__ import annotations

from rover.episode import Episode, Event, FrameFacts, GroundTruth, ObjectFacts, StateType
from rover.sim.audit import audit, expert_stalls, untouched_rises
from rover.sim.milestones import achieved, level_problems

COMPONENTS = [f"{k}:can" for k in ("approach", "contact", "pick_up", "carry", "approach_goal")]


def _f(reach=0.3, held=False, lifted=False, goal=0.4, z=0.82, contacts=(), eef=(0, 0, 1)):
    return FrameFacts(
        holding="can" if held else None,
        contacts=list(contacts),
        eef=eef,
        objects={
            "can": ObjectFacts(
                position=(0.0, 0.0, z), lifted=lifted, reach=reach, goal_distance=goal
            )
        },
    )


def test_components_from_facts_and_events():
    far, near = _f(reach=0.3), _f(reach=0.05)
    assert not achieved("approach:can", [far], []) and achieved("approach:can", [far, near], [])
    assert not achieved("approach:can", [_f(reach=0.08), _f(reach=0.06)], [])  # barely moved
    carry = [_f(held=True, lifted=True)] * 4
    assert achieved("carry:can", carry, []) and not achieved("carry:can", carry[:3], [])
    over = _f(held=True, lifted=True, goal=0.05)
    assert achieved("approach_goal:can", [over], [])
    assert not achieved("approach_goal:can", [_f(goal=0.05)], [])  # not held: not carried there
    ev = [Event(name="pick_up", object="can", frame=3), Event(name="drop", object="can")]
    assert achieved("pick_up:can", [], ev) and not achieved("drop:can", [], ev)


def test_level_needs_its_components_and_not_the_next():
    touched = [_f(reach=0.3), _f(reach=0.05)]
    contact = [Event(name="contact", object="can", frame=0)]
    assert level_problems(2, COMPONENTS, touched, []) == []  # approached, no contact
    assert any("must stop before" in p for p in level_problems(2, COMPONENTS, touched, contact))
    assert level_problems(3, COMPONENTS, touched, contact) == []
    assert any("needs 'pick_up:can'" in p for p in level_problems(4, COMPONENTS, touched, contact))
    assert level_problems(1, COMPONENTS, [_f()], []) == []
    assert level_problems(1, COMPONENTS, touched, [])  # level 1 must not even approach


def test_untouched_object_rising_is_a_teleport_but_lifting_it_is_not():
    assert untouched_rises([_f(z=0.82), _f(z=0.86)])
    assert not untouched_rises([_f(z=0.82), _f(z=0.78)])  # falling is physics
    assert not untouched_rises([_f(z=0.82, held=True), _f(z=0.86, held=True)])
    pushed = FrameFacts(robot_contacts=["can"], objects=_f(z=0.86).objects)
    assert not untouched_rises([_f(z=0.82), pushed])


def _ep(eid, level, progress, facts=None, types=None, task="Lift"):
    n = len(progress)
    return Episode(
        id=eid,
        task="t",
        frame_indices=list(range(n)),
        view_names=["v"],
        extra={"sim_task": task, "tries": 2},
        truth=GroundTruth(
            progress=progress,
            level=level,
            facts=facts or [_f() for _ in range(n)],
            state_type=types or [StateType.expert] * n,
        ),
    )


def test_expert_stall_is_four_still_expert_frames():
    still = _ep("a", 1, [0.0] * 5)
    assert expert_stalls(still)
    moving = [_f(eef=(0.0, 0.0, 1.0 + 0.01 * t)) for t in range(5)]
    assert not expert_stalls(_ep("b", 1, [0.0] * 5, facts=moving))
    mixed = [StateType.expert, StateType.non_expert] * 2 + [StateType.expert]
    assert not expert_stalls(_ep("c", 1, [0.0] * 5, types=mixed))


def test_audit_counts_per_task_and_flags_falling_level_order():
    moving = [_f(eef=(0.0, 0.0, 1.0 + 0.01 * t)) for t in range(3)]
    eps = [
        _ep("l1", 1, [0.0, 0.0, 0.3], facts=moving),
        _ep("l2", 2, [0.0, 0.1, 0.2], facts=moving),
    ]
    (a,) = audit(eps)
    assert a.task == "Lift" and a.episodes == 2 and a.tries[1] == [2]
    assert not a.ordered() and any("falls with level" in p for p in a.problems)
    assert a.milestones_met == 1  # level 1 holds; level 2 never approaches the cube


def test_every_task_lists_one_component_per_level_step():
    from rover.sim.tasks import get_task, task_names

    for name in task_names():
        spec = get_task(name)
        assert len(spec.milestones) == len(spec.levels) - 1, name
        objects = {o.name for o in spec.objects}
        assert all(c.partition(":")[2] in objects for c in spec.milestones), name
