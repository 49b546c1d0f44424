"""Predicates, goals, facts and events of the articulated fixtures (drawer, button, knob).

The fixture environments (`rover.sim.fixtures`) expose their joint; this module turns
it into what the generator speaks: end-of-subtask predicates (``drawer_opened:drawer``,
``pressed:button``, ...), the ``fixture`` goal point of the value function, per-frame
articulation facts and the events derived from them. The env wrapper, the facts code
and the experts call in here, so the core files stay fixture-agnostic; nothing here
imports robosuite (a sim that is not a fixture env simply has no articulations).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rover.episode import Event, FrameFacts

if TYPE_CHECKING:  # pragma: no cover
    from rover.sim.env import SimEnv
    from rover.sim.tasks.base import GoalSpec, TaskSpec

# thresholds on the articulation fraction, the same as the rule judge's reading of
# "x% open" (rover.eval.rule_judge), so oracle descriptions and events agree
START = 0.1  # "start opening/turning": more than this; "start closing": below FINISH
FINISH = 0.9  # "completely open/turned": at least this (the fixture's success too)
CLOSED_AT = 0.1  # "completely closed": drawer opening fraction at most this

# end signals the fixtures answer: all mean "the fixture's joint reached its target"
SIGNALS = ("drawer_opened", "drawer_closed", "door_opened", "door_closed", "pressed", "turned")
# articulated part (= task object) names; a kitchen "door" closed by its task is one too
# (an opened door's events come from `rover.sim.facts`, as robosuite's Door's)
PARTS = ("drawer", "button", "knob", "door", "stop button", "sink handle", "sink spout")
# a door a composite task works twice, opened and later closed (MicrowaveThawing)
PARTS += ("microwave door",)
# parts turned through a fraction of a target turn: dials, and the kitchen sink's
# faucet handle and swivelling spout (named for what they are)
TURNED = ("knob", "sink handle", "sink spout")
# push buttons: fact 1.0 while pressed past the switching depth; "stop button" switches
# its appliance off (the kitchen microwave's, push-to-latch), "button" switches it on
BUTTONS = ("button", "stop button")


def fixture(sim: SimEnv):
    """The fixture environment behind `sim`, or None for robosuite's own tasks."""
    env = sim.env
    return env if hasattr(env, "joint_qpos_addr") and getattr(env, "part", "") else None


def part_keys(fx) -> tuple[str, ...]:
    """The worked parts of a fixture env that works several in order (a kitchen
    composite's `parts`), by key; empty for the usual one-part env."""
    return tuple(getattr(fx, "part_keys", ()))


def signal_part(sim: SimEnv, signal: str) -> str | None:
    """The worked part whose joint the subtask ending on `signal` follows (its
    ``joint:<key>`` point); None in a one-part env."""
    keys = part_keys(fixture(sim))
    for s in sim.spec.subtasks:
        if s.end_signal == signal and s.joint and s.joint[6:] in keys:
            return s.joint[6:]
    return None


def predicate(sim: SimEnv, kind: str, obj: str) -> bool | None:
    """Evaluate ``kind:obj`` if it is a fixture signal; None when it is not one. With
    several worked parts, the part the signal's subtask follows is asked."""
    if kind == "touched":
        return obj in sim.finger_contacts()
    fx = fixture(sim)
    if kind in SIGNALS and fx is not None:
        key = signal_part(sim, f"{kind}:{obj}")
        return bool(fx.reached() if key is None else fx.reached_part(key))
    return None


def progress(sim: SimEnv, key: str) -> float:
    """Fraction of the motion to its target done by the part ``joint:<key>`` names
    (the env's one part, or the worked part `key`)."""
    fx = fixture(sim)
    if key in part_keys(fx):
        with fx.working(key):
            return float(fx.progress())
    return float(fx.progress())


def holdable(sim: SimEnv, name: str) -> bool:
    """Whether both fingers on this object mean the robot holds it (not a push button)."""
    return name not in BUTTONS


def closing(spec: TaskSpec, name: str) -> bool:
    """Whether the task closes part `name` (a drawer or door that starts open)."""
    return any(s.end_signal == f"{name}_closed:{name}" for s in spec.subtasks)


def goal(sim: SimEnv, g: GoalSpec) -> np.ndarray:
    """The ``fixture`` goal: where site `g.body` would be with the joint at its target."""
    fx = fixture(sim)
    if fx is None or g.body is None:
        raise ValueError(f"goal kind 'fixture' needs a fixture environment and a site ({g})")
    if g.object in part_keys(fx):  # one of several worked parts: at its own target
        with fx.working(g.object):
            return fx.site_at(g.body, fx.target) + np.asarray(g.offset, dtype=np.float64)
    return fx.site_at(g.body, fx.target) + np.asarray(g.offset, dtype=np.float64)


def articulation_facts(sim: SimEnv) -> tuple[dict[str, float], list[str]]:
    """Articulation fractions of the fixture part and the parts pressed down now.

    ``drawer`` (and a kitchen ``door``): opening fraction (0 closed, 1 fully open, also
    when closing it); ``button``: 1.0 while pressed past the switching depth (the
    appliance is on), else 0.0; ``stop button``: the same (1.0: the appliance is off);
    ``knob``: fraction of the target turn. An env working several parts gives each
    its own entry (a part worked twice, once: its facts do not depend on the entry).
    """
    fx = fixture(sim)
    if fx is None:
        return {}, []
    keys = part_keys(fx)
    if not keys:
        return _part_facts(fx)
    out: dict[str, float] = {}
    pressed: list[str] = []
    for key in keys:
        with fx.working(key):
            if fx.part not in out:
                facts, down = _part_facts(fx)
                out.update(facts)
                pressed += down
    return out, pressed


def _part_facts(fx) -> tuple[dict[str, float], list[str]]:
    """`articulation_facts` of the env's current part."""
    pressed = [fx.part] if fx.part in BUTTONS and fx.pressed() else []
    if fx.part in ("drawer", "door"):
        value = fx.opening()
    elif fx.part in BUTTONS:  # on/off: a half-pressed button has not switched anything
        value = 1.0 if pressed else 0.0
    else:
        value = fx.progress()
    # whole percent, as descriptions state it ("The drawer is 90% open."): events read
    # from these facts then fall on the same frame as the description that asserts them
    return {fx.part: round(float(value), 2)}, pressed


def _first(facts: list[FrameFacts], test, after: int = 0) -> int | None:
    return next((t for t, f in enumerate(facts) if t >= after and test(f)), None)


def fixture_events(spec: TaskSpec, name: str, facts: list[FrameFacts]) -> list[Event]:
    """Events of an articulated part, the first frame at which the facts show each.

    drawer: grasp, open_start/open_finish (or close_start/close_finish when the task
    closes it, as for a kitchen door that starts open); button: press and turn_on (the
    appliance switches on as the button bottoms out), stop button: press and turn_off;
    knob (sink handle, sink spout): grasp, turn_start, turn_finish.
    """

    def value(f: FrameFacts) -> float:
        return f.articulations.get(name, 0.0)

    def ev(event: str, frame: int | None) -> Event:
        return Event(name=event, object=name, frame=frame)

    signals = {s.end_signal.partition(":")[0] for s in spec.subtasks}
    # a grasp, as for free objects: a hold begins (both fingers on it, moving with the hand)
    grasp = ev("grasp", _first(facts, lambda f: f.holding == name))
    own = {s.end_signal for s in spec.subtasks if s.object == name}
    if {f"door_opened:{name}", f"door_closed:{name}"} <= own:  # opened, later closed
        opened = _first(facts, lambda f: value(f) >= FINISH)
        after = opened if opened is not None else len(facts)
        return [
            grasp,
            ev("open_start", _first(facts, lambda f: value(f) > START)),
            ev("open_finish", opened),
            ev("close_start", _first(facts, lambda f: value(f) < FINISH, after)),
            ev("close_finish", _first(facts, lambda f: value(f) <= CLOSED_AT, after)),
        ]
    if name in ("drawer", "door") and f"{name}_closed" in signals:
        return [
            grasp,
            ev("close_start", _first(facts, lambda f: value(f) < FINISH)),
            ev("close_finish", _first(facts, lambda f: value(f) <= CLOSED_AT)),
        ]
    if name == "drawer":
        return [
            grasp,
            ev("open_start", _first(facts, lambda f: value(f) > START)),
            ev("open_finish", _first(facts, lambda f: value(f) >= FINISH)),
        ]
    if name in BUTTONS:
        press = _first(facts, lambda f: name in f.pressed)
        return [ev("press", press), ev("turn_off" if name == "stop button" else "turn_on", press)]
    if name in TURNED:
        return [
            grasp,
            ev("turn_start", _first(facts, lambda f: value(f) > START)),
            ev("turn_finish", _first(facts, lambda f: value(f) >= FINISH)),
        ]
    return []
