"""Stitching ROVER's per-line subtask progress into one curve over the full task.

Paper Sec. 5.1: "we divide the values within each subtask by the total number of
subtasks and add them to the value for the last timestep of the previous subtask". A line
whose values are worth `scale` points of the full task, starting from full-task value
`base`, maps its subtask i's value p to `base_i + scale * p / (100 n)`, where `base_0` is
the line's base and `base_(i+1)` the full-task value at subtask i's last frame; nested
lines compose the same way. So with n = 2, a video that stops at 70% of subtask 1 scores
35, and a subtask 1 that ended at 90% hands subtask 2 a start of 45.

n is the length of the plan the model announced ("New subtasks: [...]"), grown only when
it adds subtasks beyond it. Values are not clipped (negative progress after a regression
is kept, as the prompts ask); frames nobody predicted are filled forward; frame 0 is 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Point:
    """A progress value (0-100 within its line) the model gave for one frame position."""

    position: int
    progress: float


@dataclass
class StitchLine:
    """One line of reasoning: its own points and its children, in the order they happened.

    `first_position` is the line's "initial robot scene" (0% by definition): it counts
    only for frames nothing else predicted.
    """

    first_position: int
    items: list[Point | StitchLine] = field(default_factory=list)
    planned: int = 0  # number of subtasks the model announced, 0 if it gave no plan

    @property
    def children(self) -> list[StitchLine]:
        return [c for c in self.items if isinstance(c, StitchLine)]

    @property
    def n_subtasks(self) -> int:
        return max(self.planned, len(self.children))


@dataclass
class Value:
    """One frame's stitched value and the line point it came from."""

    progress: float
    raw: float
    line: StitchLine


def point_value(base: float, scale: float, progress: float) -> float:
    """Full-task value of a line's answer `progress` (0-100 of the line)."""
    return base + scale * progress / 100.0


def child_scale(scale: float, n_subtasks: int) -> float:
    """Points of the full task one of a line's `n_subtasks` subtasks is worth."""
    return scale / max(n_subtasks, 1)


def line_values(
    line: StitchLine, base: float = 0.0, scale: float = 100.0
) -> tuple[dict[int, Value], dict[int, float], float]:
    """Full-task values of a line's predictions (later ones win), of its anchors, and its end.

    Returns (predicted, anchors, end): `predicted[pos]` from the model's answers,
    `anchors[pos]` the 0% start of each line mapped to the full task (used only where
    nothing was predicted), and `end`, the full-task value at the line's last answer.
    """
    predicted: dict[int, Value] = {}
    anchors: dict[int, float] = {line.first_position: base}
    sub_scale = child_scale(scale, line.n_subtasks)
    start = end = base  # start: the value at the previous subtask's last frame
    for item in line.items:
        if isinstance(item, Point):
            # a decomposed line's own answers are on its own 0-100 scale
            end = point_value(base, scale, item.progress)
            predicted[item.position] = Value(end, item.progress, line)
        else:
            sub_pred, sub_anchor, end = line_values(item, start, sub_scale)
            predicted.update(sub_pred)
            for pos, v in sub_anchor.items():
                anchors.setdefault(pos, v)
            start = end
    return predicted, anchors, end


def fill_forward(values: list[float | None], first: float = 0.0) -> list[float]:
    """Replace missing values with the previous known one; frame 0 is `first` (0)."""
    out: list[float] = []
    last = first
    for i, v in enumerate(values):
        if i == 0:
            last = first
        elif v is not None:
            last = v
        out.append(last)
    return out


def stitch(root: StitchLine, num_frames: int) -> tuple[list[float], dict[int, Value]]:
    """One curve over the full task (per frame position) plus the per-frame sources."""
    predicted, anchors, _ = line_values(root)
    raw: list[float | None] = []
    for pos in range(num_frames):
        if pos in predicted:
            raw.append(predicted[pos].progress)
        else:
            raw.append(anchors.get(pos))
    return fill_forward(raw), predicted
