"""Where a level's video leaves the expert, read from the expert's own demo.

A level of App. B Table 5 means "components 1..L-1 achieved, component L not". Cutting
at a fixed fraction of a subtask's expert steps ignores when the expert actually
achieves each component, so the random ending often completed the next one or had not
reached the current one. Here the facts of every expert step are read once per demo (no
rendering) and `ExpertMarks` records the first step at which each milestone component
(`TaskSpec.milestones`) holds, plus when each hold begins and ends; `cut_window` turns
a level into the stretch of expert steps where its video may stop following the expert:
after component L-1, before component L (and, for the components an ending must not
cause, before the hold or release that would cause it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rover.episode import FrameFacts
from rover.sim.levels import LevelSpec, component_kind
from rover.sim.milestones import achieved
from rover.sim.tasks.base import TaskSpec

CARRY_WINDOW_FRAMES = 1.0  # a "picked up, not carried" video lets go within a frame


@dataclass(frozen=True)
class ExpertMarks:
    """Milestone steps of one (trimmed) expert demo.

    Attributes:
        steps: per component of the task, the first expert step at which the prefix of
            the demo up to it shows the component (None: the expert never shows it).
        holds: object -> (first held step, first step after the hold or None) per hold.
        length: number of expert steps.
    """

    steps: tuple[int | None, ...]
    holds: dict[str, tuple[tuple[int, int | None], ...]]
    length: int


def expert_marks(spec: TaskSpec, facts: Sequence[FrameFacts]) -> ExpertMarks:
    """Find each component's first step by bisection over prefixes of the facts.

    Every component kind is monotone in the prefix (once a prefix shows it, every
    longer one does), so bisection finds the first step in log2(T) checks.
    """
    from rover.sim.facts import detect_events, hold_spans

    facts = list(facts)
    n = len(facts)

    def shows(comp: str, t: int) -> bool:
        head = facts[: t + 1]
        return achieved(comp, head, detect_events(spec, head))

    steps: list[int | None] = []
    for comp in spec.milestones:
        if not n or not shows(comp, n - 1):
            steps.append(None)
            continue
        lo, hi = 0, n - 1
        while lo < hi:
            mid = (lo + hi) // 2
            if shows(comp, mid):
                hi = mid
            else:
                lo = mid + 1
        steps.append(lo)
    holds = {o.name: tuple(hold_spans(facts, o.name)) for o in spec.objects}
    return ExpertMarks(tuple(steps), holds, n)


def _all_shown(marks: ExpertMarks, k: int) -> int | None:
    """The first step by which the expert has shown components 1..k (0 for none; None
    if it never shows one). Usually component k's step, but not always: a Stack demo
    may grasp the red cube already within reach of the green one ("over the target"
    before "carry")."""
    got = marks.steps[:k]
    if any(s is None for s in got):
        return None
    return max(got, default=0)


def _hold_after(marks: ExpertMarks, obj: str, t: int) -> tuple[int, int | None] | None:
    for start, end in marks.holds.get(obj, ()):
        if end is None or end > t:
            return start, end
    return None


def _next_component(level: LevelSpec, components: Sequence[str]) -> str | None:
    """The component a cut level fails (its L-th), or None for a level that is not cut
    by milestone (the top level, a level without `milestone_cut`, one past the list)."""
    L = level.level
    if level.completes or level.milestone_cut is None or L - 1 >= len(components):
        return None
    return components[L - 1]


def cut_window(
    level: LevelSpec,
    components: Sequence[str],
    marks: ExpertMarks,
    frames: int,
) -> tuple[int, int] | None:
    """Inclusive expert steps ``(lo, hi)`` where a video of `level` may leave the expert.

    From the step component L-1 is first shown (0 for level 1) to the step before
    component L is: pre-grasp components end the stretch before the hand takes the
    object; "place" ends it before the hold ends (the ending keeps holding); "carry" is
    the `CARRY_WINDOW_FRAMES` video frames after the pick-up (the ending lets go, so the
    video shows the object held off its start for fewer frames than "carry" needs).
    None when the demo never shows a component the level needs, or the stretch is empty.
    """
    L = level.level
    nxt = _next_component(level, components)
    if nxt is None:
        return None
    kind = component_kind(nxt)
    obj = nxt.partition(":")[2]
    lo = _all_shown(marks, L - 1)
    if lo is None:
        return None
    t_next = marks.steps[L - 1]
    hi = (marks.length - 1) if t_next is None else t_next - 1
    if kind in ("pick_up", "grasp", "start"):
        hold = _hold_after(marks, obj, lo)
        if hold is not None and hold[0] >= lo:  # (at the contact itself when both coincide)
            if kind == "pick_up" and hold[0] == lo and lo > 0:
                return None  # the hold starts with the contact: nothing touched-not-held
            hi = min(hi, max(hold[0] - 1, lo))
    elif kind == "place":
        hold = _hold_after(marks, obj, lo)
        if hold is not None and hold[1] is not None:
            hi = min(hi, hold[1] - 1)
    elif kind == "carry":
        # "carry" counts video frames, not expert steps: frames are spaced by (steps of
        # the video) / (frames - 1), and the video runs to about the cut plus the ending
        w = sum(level.terminal_w) / 2
        span = CARRY_WINDOW_FRAMES / max(frames - 1, 1)
        hi = min(marks.length - 1, int((lo + span * w) / max(1.0 - span, 0.1)))
    if hi < lo:
        return None
    return int(lo), int(hi)


def held_contact_window(
    level: LevelSpec, components: Sequence[str], marks: ExpertMarks
) -> tuple[int, int] | None:
    """Where a "touched, not picked up" video leaves a demo whose hold starts with its contact.

    When both fingers close on the object at the very step of the first touch (a milk
    carton squeezed square-on), the demo has no touched-not-held stretch and
    `cut_window` gives none. The video then leaves the expert at that step: the frame
    shows the fingers on the object, and the level's ending opens them and backs the
    hand off, without lifting it. (A hold in which the object never moves ends in
    neither a drop nor a place: `rover.sim.facts.releases`.) None for any other case.
    """
    L = level.level
    nxt = _next_component(level, components)
    if nxt is None or component_kind(nxt) != "pick_up":  # (a hold shows as "grasp")
        return None
    lo = _all_shown(marks, L - 1)
    if lo is None or lo == 0:
        return None
    hold = _hold_after(marks, nxt.partition(":")[2], lo)
    if hold is None or hold[0] != lo:
        return None
    return int(lo), int(lo)


def draw_cut(window: tuple[int, int], level: LevelSpec, rng: np.random.Generator) -> int:
    """The expert step the video leaves at: ``level.milestone_cut`` of the window."""
    lo, hi = window
    a, b = level.milestone_cut or (0.0, 1.0)
    f = float(rng.uniform(a, b)) if b > a else float(a)
    return lo + int(round(f * (hi - lo)))


BAND_UNDO = 0.1  # progress an ending may lose below the component the level achieved
BAND_GAP = 0.02  # "moved off": a touched-not-held level ends this far below the contact


# articulated: a "contact" video may end this far under the expert at the contact, as
# any ending may undo `BAND_UNDO` of what its level achieved
TOUCH_GAP = BAND_UNDO


def touch_line(approach: float, contact: float) -> float:
    """The progress between an articulated part's "approached, not touched" videos (below)
    and its "touched, not started" ones (above): half way from the expert's progress at
    the approach to that at the contact, but at least `TOUCH_GAP` under the contact. The
    contact level's ending rests the open hand at the handle or knob, worth a little less
    than the expert's closing fingers, and the approach level's backs the hand off
    (`rover.sim.levels.ENDINGS_BY_KIND`); where the expert's progress hardly changes
    between the approach and the contact (a kitchen cabinet's handle) the
    midpoint left the resting hand no room (its open fingers lose up to 0.08 against
    the expert's closing ones)."""
    return min((approach + contact) / 2, contact - TOUCH_GAP)


def progress_band(
    level: LevelSpec, components: Sequence[str], marks: ExpertMarks, expert: np.ndarray
) -> tuple[float, float] | None:
    """``(floor, ceiling)`` of a level's final progress, from the expert's progress at
    its components (`expert`: progress per expert step), so the bands rise with the
    level and so does the final progress (the audit's order check):

    * in general the ending may undo at most `BAND_UNDO` of what the level achieved:
      floor = progress at component L-1, less `BAND_UNDO`;
    * "approached, not touched" ends below half way from the approach to the contact,
      and "touched, not held" (the hand leaves before the grasp) between that and
      `BAND_GAP` below the contact;
    * "picked up, not carried" lets go, and the object lies where it was touched: at
      least `BAND_GAP` below the contact.

    The touched-not-held band needs the contact right before: Restock's "placed the milk,
    not yet picked up the can" is a general level (its achievement is a placement).

    None when the demo does not show the components the band reads.
    """
    L = level.level
    if level.completes or L - 1 >= len(components):
        return None
    kind = component_kind(components[L - 1])
    s = marks.steps

    def at(i: int) -> float | None:  # progress at component i (0-based); -1: the start
        if i < 0:
            return 0.0
        return None if s[i] is None else float(expert[s[i]])

    if L == 1:
        return 0.0, 1.0
    shown = _all_shown(marks, L - 1)
    if shown is None:
        return None
    here = float(expert[shown])
    if kind == "contact":
        nxt = at(L - 1)
        if nxt is not None and L < len(components) and component_kind(components[L]) == "start":
            return max(here - BAND_UNDO, 0.0), touch_line(here, nxt)  # (a handle or knob)
        return max(here - BAND_UNDO, 0.0), 1.0 if nxt is None else (here + nxt) / 2
    after_contact = component_kind(components[L - 2]) == "contact"
    if kind == "start" and after_contact:
        before = at(L - 3)
        return None if before is None else (touch_line(before, here), 1.0)
    if kind == "pick_up" and after_contact and level.terminal_drift[2] > 0:
        before = at(L - 3)
        if before is None:
            return None
        # touched, not held, the open hand backing off upwards (the pick-and-place
        # ending): from half `BAND_UNDO` under the approach up to the contact. The
        # approach and the contact are often only 0.02-0.05 apart in progress, too
        # close to hold a random ending above their midpoint
        return max(before - BAND_UNDO / 2, 0.0), here
    if kind == "carry" and level.terminal_settle[1] > 0:
        # set back down in the grasp, then let go with the open hand at it (the
        # pick-and-place ending): an open hand at the object is worth about what it
        # was at the contact, a little more or less with where the fingers are (the
        # closed fingers were part of the grasp's value); above the midpoint of the
        # approach and the contact (where a touched-not-held hand that backs off ends)
        # and below the pick-up (it is not carried)
        app, con, pick = at(L - 4), at(L - 3), at(L - 2)
        if app is None or con is None or pick is None:
            return None
        return (app + con) / 2, max(pick - BAND_GAP, 0.0)
    if kind in ("pick_up", "grasp", "start") and after_contact:
        before = at(L - 3)
        if before is None:
            return None
        # (an object let go after its pick-up lies where it was touched: this level must
        # end below that; a handle let go is never part of a level, so no ceiling there)
        top = max(here - BAND_GAP, 0.0) if kind != "start" else 1.0
        return (before + here) / 2, top
    if kind == "carry":
        before = at(L - 3)
        return (max(before - BAND_GAP, 0.0) if before is not None else 0.0), 1.0
    return max(here - BAND_UNDO, 0.0), 1.0
