"""Stitching ROVER's per-line subtask progress into one 0-100 curve over the full task.

Paper Sec. 5.1 / App. E: within a line of reasoning that ended up with n subtasks, the
i-th subtask (0-based) covers `100*i/n .. 100*(i+1)/n` of its parent's range, so a child
value p maps to `100*i/n + p/n`; nesting composes the same mapping. n is the number of
subtasks the line ended up with, or the number it announced up front when the model gave
a plan ("New Subtasks: [...]"), whichever is larger. Frames nobody predicted are filled
forward; frame 0 is 0.
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


def _clamp(p: float, lo: float = -100.0, hi: float = 100.0) -> float:
    return min(max(p, lo), hi)


def line_values(
    line: StitchLine, lo: float = 0.0, hi: float = 100.0
) -> tuple[dict[int, Value], dict[int, float]]:
    """Full-task values of a line's predictions (later ones win) and of its anchors.

    Returns (predicted, anchors): `predicted[pos]` from the model's answers, `anchors[pos]`
    the 0% start of each line mapped to the full task, used only where nothing was predicted.
    """
    predicted: dict[int, Value] = {}
    anchors: dict[int, float] = {line.first_position: lo}
    n = line.n_subtasks
    child_i = 0
    for item in line.items:
        if isinstance(item, Point):
            # a decomposed line's own answers are on its own 0-100 scale
            v = lo + (hi - lo) * _clamp(item.progress) / 100.0
            predicted[item.position] = Value(v, item.progress, line)
        else:
            c_lo = lo + (hi - lo) * child_i / n
            c_hi = lo + (hi - lo) * (child_i + 1) / n
            sub_pred, sub_anchor = line_values(item, c_lo, c_hi)
            predicted.update(sub_pred)
            for pos, v in sub_anchor.items():
                anchors.setdefault(pos, v)
            child_i += 1
    return predicted, anchors


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
    """One curve over the full task (0-100 per frame position) plus the per-frame sources."""
    predicted, anchors = line_values(root)
    raw: list[float | None] = []
    for pos in range(num_frames):
        if pos in predicted:
            raw.append(predicted[pos].progress)
        else:
            raw.append(anchors.get(pos))
    curve = [min(max(v, 0.0), 100.0) for v in fill_forward(raw)]
    return curve, predicted
