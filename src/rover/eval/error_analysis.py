"""Error analysis in the App. D categories, derived automatically per video.

The paper hand-labelled 200 videos; we derive the same four categories from the judge's
verdicts, the predicted progress and the ground-truth subtask structure, so the table can
be produced for any run. Each rule marks a *video* as containing at least one occurrence:

- perception error: at least one frame description judged verifiably false (Task 2).
- reasoning error: a frame whose description is *not* judged false, where the predicted
  progress moves by at least `REASONING_DELTA` points (0..100) in the opposite direction
  to the ground truth over the same step (App. D: "correctly identifies the gripper has
  dropped an object, states that task progress is increasing").
- incorrect subtask (methods with a reasoning tree only): a line of reasoning whose
  subtask text names none of the objects of the ground-truth subtasks active during that
  line's frames (or the subtasks right before/after them).
- redundant subtask (tree only): a line whose subtask repeats an ancestor's or earlier
  sibling's text, or matches (same action class and object) a ground-truth subtask that
  had already ended before the line began.

"Other" errors in the paper are whatever a human saw beyond these; they are not derived.
Methods without a tree report NA for the two subtask rows, as in the paper's table.
"""

from __future__ import annotations

import re
from typing import Any

from rover.episode import Episode, Subtask
from rover.eval.aggregate import finite_or_none, mean_se
from rover.eval.judge import Judgements
from rover.eval.progress_metrics import align
from rover.methods.trace import LineNode, Trace

REASONING_DELTA = 10.0
ERROR_TYPES = ("incorrect_subtask", "redundant_subtask", "perception", "reasoning")

_ACTIONS = {
    "pick": ("pick", "grasp", "grab", "lift", "take", "hold"),
    "place": ("place", "put", "drop", "insert", "move", "carry", "transport", "bring", "set"),
    "open": ("open", "pull"),
    "close": ("close", "shut"),
    "press": ("press", "push", "start", "activate"),
    "turn": ("turn", "rotate", "twist", "toggle"),
    "reach": ("reach", "approach", "go"),
}


def action_class(text: str) -> str | None:
    words = re.findall(r"[a-z]+", text.lower())
    for w in words:
        for cls, verbs in _ACTIONS.items():
            if any(w.startswith(v) for v in verbs):
                return cls
    return None


def _objects(sub: Subtask) -> list[str]:
    if sub.object:
        return [sub.object.lower().replace("_", " ")]
    words = [w for w in re.findall(r"[a-z]+", sub.name.lower()) if len(w) > 2]
    return [w for w in words if action_class(w) is None and w not in {"the", "and", "into"}]


def _mentions(text: str, obj: str) -> bool:
    """Does `text` name `obj` (any of its words, as whole words, plural allowed)?"""
    words = set(re.findall(r"[a-z0-9]+", text.lower()))
    return any(
        tok in words or tok + "s" in words
        for tok in re.findall(r"[a-z0-9]+", obj.lower())
        if len(tok) > 2 and not tok.isdigit()
    )


def _lines(node: LineNode | None) -> list[tuple[LineNode, list[LineNode], list[LineNode]]]:
    """(line, ancestors, earlier siblings) for every line below the root."""
    out: list[tuple[LineNode, list[LineNode], list[LineNode]]] = []

    def walk(n: LineNode, ancestors: list[LineNode]) -> None:
        for i, child in enumerate(n.children):
            out.append((child, ancestors + [n], n.children[:i]))
            walk(child, ancestors + [n])

    if node is not None:
        walk(node, [])
    return out


def _norm(text: str) -> str:
    return " ".join(re.findall(r"[a-z0-9]+", text.lower()))


def video_errors(trace: Trace, episode: Episode, judgements: Judgements | None) -> dict[str, Any]:
    """0/1 per error type for one video (None where the rule does not apply)."""
    out: dict[str, Any] = {k: None for k in ERROR_TYPES}
    bad = {v.index for v in judgements.verdicts if v.verdict == "false"} if judgements else set()
    if judgements is not None and judgements.has_facts:
        out["perception"] = int(bool(bad))
    # frame-number truth (real videos) rises every frame, so any predicted drop would
    # "contradict" it: the reasoning rule only applies to measured progress
    if episode.truth is not None and episode.truth.progress_source != "frame_number":
        a = align(trace, episode)
        flag = 0
        for i in range(1, len(a.indices)):
            dp, dt = a.predicted[i] - a.predicted[i - 1], a.truth[i] - a.truth[i - 1]
            opposite = (dp >= REASONING_DELTA and dt < 0) or (dp <= -REASONING_DELTA and dt > 0)
            if opposite and a.indices[i] not in bad:
                flag = 1
                break
        out["reasoning"] = flag
    if trace.tree is not None and episode.truth is not None and episode.truth.subtasks:
        out.update(_subtask_errors(trace, episode))
    return out


def _subtask_errors(trace: Trace, episode: Episode) -> dict[str, int]:
    subs = sorted(episode.truth.subtasks, key=lambda s: s.start)  # type: ignore[union-attr]
    where = {idx: pos for pos, idx in enumerate(episode.frame_indices)}
    last_pos = episode.num_frames - 1

    def pos_of(idx: int | None, default: int) -> int:
        if idx is None:
            return default
        if idx in where:
            return where[idx]
        return min(
            range(len(episode.frame_indices)), key=lambda p: abs(episode.frame_indices[p] - idx)
        )

    incorrect = redundant = 0
    for line, ancestors, siblings in _lines(trace.tree):
        start = pos_of(line.first_frame, 0)
        end = pos_of(line.last_frame, last_pos)
        active = [i for i, s in enumerate(subs) if s.start <= end and s.end >= start]
        near = set(active) | {i - 1 for i in active} | {i + 1 for i in active}
        objs = [o for i in sorted(near) if 0 <= i < len(subs) for o in _objects(subs[i])]
        if objs and not any(_mentions(line.subtask, o) for o in objs):
            incorrect = 1
        text = _norm(line.subtask)
        if any(_norm(x.subtask) == text for x in ancestors[1:] + siblings):
            redundant = 1
            continue
        cls = action_class(line.subtask)
        for s in subs:
            if (
                s.end < start
                and cls is not None
                and action_class(s.name) == cls
                and any(_mentions(line.subtask, o) for o in _objects(s))
            ):
                # the same action on the same object, finished before this line began
                if not any(
                    t.start >= start
                    and action_class(t.name) == cls
                    and any(_mentions(line.subtask, o) for o in _objects(t))
                    for t in subs
                ):
                    redundant = 1
    return {"incorrect_subtask": incorrect, "redundant_subtask": redundant}


def error_table(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Percentage of videos (mean ± SE of the 0/1 flags) with each error type, per variant."""
    out = []
    variants = sorted({r["variant"] for r in rows})
    for v in variants:
        vr = [r for r in rows if r["variant"] == v and not r.get("error")]
        if not vr:
            continue
        flags = {k: [r.get(f"err_{k}") for r in vr] for k in ERROR_TYPES}
        total = [
            None
            if all(flags[k][i] is None for k in ERROR_TYPES)
            else int(any(flags[k][i] for k in ERROR_TYPES))
            for i in range(len(vr))
        ]
        for k, vals in list(flags.items()) + [("total", total)]:
            mean, se, n = mean_se([100.0 * x for x in vals if x is not None])  # % of videos
            out.append(
                {
                    "variant": v,
                    "method": vr[0]["method"],
                    "error_type": k,
                    "mean": finite_or_none(mean),
                    "se": finite_or_none(se),
                    "n": n,
                }
            )
    return out
