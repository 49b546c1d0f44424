"""ROVER: recursive lines of reasoning over a video (paper Sec. 3, Algorithm 1, App. E.2).

Algorithm 1, as implemented by `Rover._line` (comments cite its line numbers):

    1  function ROVER(c, Y)
    2    while True
    3      Y = Y + Θ(c + Y)                      one VLM call on the windowed context
    4      if Y progresses to next frame         "Subtask completion percentage: N%" [next-frame]
    5        Y = Y + o_next                      Y = Window(Y + o_next)
    6      elif Y specifies a new task           "The robot needs to: <subtask>"
    7        Y = Y + ψ(ROVER(φ(Y), []))          child line; then the parent turn (ψ)
    8      elif Y indicates task complete        ≥ threshold, "Task complete", or end of video
    9        return Y

φ gives the child its subtask and the parent's last frame (with its description) as the
child's "initial robot scene" at 0%; ψ hands back the child's final frame and final
description. After a child returns, the parent gets a turn showing its plan, what is done,
and the child's final frame with its description ("The robot has completed: ..."), and
answers with the next subtask or "Task complete" (or, rarely, its own progress, and then
it carries on frame by frame itself).

Plans are part of the protocol: a decomposition answers "New subtasks: [...]" then "The
robot needs to: <first>", as the paper's examples and the public reference code do. The
plan's length is the n that stitching divides by (grown only if the model adds subtasks).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from rover.episode import Episode
from rover.errors import InputError
from rover.methods.base import Method, OnStep, Session, text
from rover.methods.parse import StepReply, parse_step
from rover.methods.prompts import pct, render
from rover.methods.stitch import Point, StitchLine, child_scale, point_value, stitch
from rover.methods.trace import LineNode, Trace
from rover.methods.window import Seen, validate_window, window_frames
from rover.vlm.types import VLM, ImagePart, TextPart

PrevFramePolicy = Literal["always", "on_change"]


@dataclass
class _Line:
    """State of one line of reasoning while it runs."""

    id: int
    subtask: str
    path: list[str]  # subtask chain from the root task (root excluded)
    depth: int
    first: Seen  # the line's initial robot scene (0% by definition)
    node: LineNode
    stitch: StitchLine
    history: list[Seen] = field(default_factory=list)  # candidates for "previous frame"
    completed: list[str] = field(default_factory=list)
    plan: list[str] = field(default_factory=list)
    last_progress: float = 0.0
    last_description: str | None = None
    last_position: int = 0
    # live stitching (stitch.py's rule applied as the line runs, for `StepInfo.total`):
    # the full-task value of this line's 0%, the points 100% of it is worth, the value at
    # its last finished child's end (where the next child starts) and at its last answer
    base: float = 0.0
    scale: float = 100.0
    start: float = 0.0
    end: float = 0.0


# A step's percentage outside this range is not a reading of the frame (a first reply of
# "250%" would otherwise end the line after one call): it is re-asked with the format
# reminder, and if the second reply is no better the step carries the last value.
PLAUSIBLE_PROGRESS = (-100.0, 150.0)


def _plausible(reply: StepReply) -> bool:
    lo, hi = PLAUSIBLE_PROGRESS
    return reply.progress is not None and lo <= reply.progress <= hi


class Rover(Method):
    """ROVER with a sliding window of `window` frames (None: the whole line).

    Params: window (3), threshold (100: a line ends when its progress reaches it),
    max_depth (3: deepest nesting of subtasks), max_subtasks (8 per line), recursion
    (True; False gives the no-recursion ablation), prev_frame_policy ("always": the paper's
    text, the most recent previous frame is the previous step; "on_change": the public
    reference code, it only moves when the predicted progress changes).
    """

    name = "rover"

    def __init__(
        self,
        window: int | None = 3,
        threshold: float = 100.0,
        max_depth: int = 3,
        max_subtasks: int = 8,
        recursion: bool = True,
        prev_frame_policy: PrevFramePolicy = "always",
        max_tokens: int | None = None,
        tokens_per_frame: int | None = None,
        **_ignored: Any,
    ) -> None:
        if prev_frame_policy not in ("always", "on_change"):
            raise InputError(
                f"prev_frame_policy must be 'always' or 'on_change', got {prev_frame_policy!r}"
            )
        if max_depth < 0 or max_subtasks < 1:
            raise InputError("max_depth must be >= 0 and max_subtasks >= 1")
        super().__init__(
            window=validate_window(window),
            threshold=float(threshold),
            max_depth=int(max_depth),
            max_subtasks=int(max_subtasks),
            recursion=bool(recursion),
            prev_frame_policy=prev_frame_policy,
        )
        self.budget_options(max_tokens, tokens_per_frame)
        self.window = window
        self.threshold = float(threshold)
        self.max_depth = int(max_depth) if recursion else 0
        self.max_subtasks = int(max_subtasks)
        self.policy: PrevFramePolicy = prev_frame_policy

    async def run(self, episode: Episode, vlm: VLM, on_step: OnStep | None = None) -> Trace:
        vlm = vlm.bind(episode)
        s = Session(self, episode, vlm, on_step)  # all per-run state lives on s
        return self.stitched(s, await self.reason(s, episode.task))

    async def reason(self, s: Session, task: str) -> _Line:
        """Algorithm 1 over the frames `s` gives; returns the ended root line.

        The one implementation for finished videos (`run`) and live streams
        (`rover.stream.RoverStream`, whose session waits for each pushed frame in
        `has_frame`): frames are asked for strictly in order, and the video ends when
        `has_frame` says there is no next frame.
        """
        # ROVER(c, []) with c = task description + first observation (Sec. 3)
        root = self._new_line(s, task, [], 0, Seen(0, None, 0.0))
        await self._line(s, root)
        return root

    def stitched(self, s: Session, root: _Line) -> Trace:
        """The finished trace: every frame's stitched full-task value, the line tree."""
        curve, sources = stitch(root.stitch, s.num_frames)
        for pos, fr in enumerate(s.trace.frames):
            fr.progress = curve[pos]
            fr.predicted = pos in sources
        s.trace.tree = root.node
        return s.finish()

    # -- lines of reasoning ---------------------------------------------------------------

    def _new_line(
        self, s: Session, subtask: str, path: list[str], depth: int, first: Seen
    ) -> _Line:
        node = LineNode(
            id=s.lines_started,
            subtask=subtask,
            depth=depth,
            first_frame=s.frame_index(first.position),
            first_position=first.position,
        )
        s.lines_started += 1
        return _Line(
            id=node.id,
            subtask=subtask,
            path=path,
            depth=depth,
            first=first,
            node=node,
            stitch=StitchLine(first_position=first.position),
            last_position=first.position,
            last_description=first.description,
        )

    def _can_decompose(self, line: _Line) -> bool:
        return line.depth < self.max_depth and len(line.node.children) < self.max_subtasks

    async def _line(self, s: Session, line: _Line) -> _Line:
        """Algorithm 1 for one line; returns it ended (ψ reads its final frame/description)."""
        s.open_lines.append(line)
        try:
            return await self._run_line(s, line)
        finally:
            s.open_lines.pop()

    async def _run_line(self, s: Session, line: _Line) -> _Line:
        # the root's first call looks at frame 0 itself; a child starts from φ's frame
        t = line.first.position if line.first.description is None else line.first.position + 1
        while True:  # Alg. 1 line 2
            if not await s.has_frame(t):  # end of the video ends every open line
                return self._end(s, line, "end_of_video")
            reply, ok = await self._step(s, line, t)  # line 3: Y = Y + Θ(c + Y)
            fr = s.trace.frames[t]
            if reply.description:
                fr.description = reply.description
                line.last_description = reply.description
            line.last_position = t
            if t == line.first.position:
                line.first = Seen(t, reply.description, 0.0)
            if not ok:  # unusable twice: record nothing, carry the last value, move on
                s.step(t, line.path, line.last_progress, line.end)
                t += 1
                continue
            if reply.new_subtask and self._can_decompose(line):  # line 6: new task
                self._take_plan(line, reply)
                anchor = Seen(t, reply.description or line.last_description, 0.0)
                s.step(t, [*line.path, reply.new_subtask], None, line.start)
                child = await self._child(s, line, reply.new_subtask, anchor)  # line 7
                nxt = await self._after_children(s, line, child)
                if nxt is None:
                    return line
                t = nxt
            elif reply.progress is not None:  # line 4: [next-frame]
                self._record(s, line, t, reply)
                if reply.progress >= self.threshold:  # line 8: subtask complete
                    return self._end(s, line, "complete")
                t += 1  # line 5: Y = Window(Y + o_next)
            else:  # line 8: "Task complete"
                reply.progress = 100.0
                self._record(s, line, t, reply)
                return self._end(s, line, "complete")  # line 9

    async def _child(self, s: Session, parent: _Line, subtask: str, anchor: Seen) -> _Line:
        """φ(Y) -> ROVER(φ(Y), []) -> the ended child, whose final frame ψ returns."""
        child = self._new_line(s, subtask, [*parent.path, subtask], parent.depth + 1, anchor)
        parent.node.children.append(child.node)
        parent.stitch.items.append(child.stitch)
        n = max(parent.stitch.planned, len(parent.node.children))
        child.base, child.scale = parent.start, child_scale(parent.scale, n)
        child.start = child.end = child.base
        fr = s.trace.frames[anchor.position]
        if not fr.predicted:
            fr.subtask_path, fr.subtask_progress = list(child.path), 0.0
        return await self._line(s, child)

    async def _after_children(self, s: Session, line: _Line, child: _Line) -> int | None:
        """Text-only parent turns after a child returns (ψ): next subtask, or done.

        Returns the next frame position for the line's own steps, or None when the line
        has ended.
        """
        while True:
            line.completed.append(child.subtask)
            line.last_position = child.last_position
            line.last_description = child.last_description
            line.start = line.end = child.end
            if child.node.outcome == "end_of_video" or not await s.has_frame(
                child.last_position + 1
            ):
                return self._end_none(s, line, "end_of_video")
            reply, ok = await self._parent_turn(s, line, child)
            f = child.last_position
            if ok:
                self._take_plan(line, reply)
            want_more = ok and reply.new_subtask is not None
            if not ok and len(line.plan) > len(line.completed):
                want_more, reply.new_subtask = True, line.plan[len(line.completed)]
            if want_more and reply.new_subtask:
                if len(line.node.children) >= self.max_subtasks:
                    return self._end_none(s, line, "guard")
                anchor = Seen(f, child.last_description, 0.0)
                child = await self._child(s, line, reply.new_subtask, anchor)
                continue
            if ok and reply.progress is not None:
                line.last_position = f
                self._record(s, line, f, reply, overwrite=False)
                if reply.progress >= self.threshold:
                    return self._end_none(s, line, "complete")
            elif ok:  # "Task complete"
                return self._end_none(s, line, "complete")
            return f + 1  # carry on frame by frame in this line

    def _take_plan(self, line: _Line, reply: StepReply) -> None:
        """A plan the model announced sets n; a longer one later replaces it."""
        if reply.plan and len(reply.plan) > len(line.plan):
            line.plan = list(reply.plan)
            line.node.planned_subtasks = list(reply.plan)
            line.stitch.planned = max(line.stitch.planned, len(reply.plan))

    def _end(self, s: Session, line: _Line, outcome: str) -> _Line:
        line.node.outcome = outcome  # type: ignore[assignment]
        line.node.last_position = line.last_position
        line.node.last_frame = s.frame_index(line.last_position)
        line.node.final_description = line.last_description
        return line

    def _end_none(self, s: Session, line: _Line, outcome: str) -> None:
        self._end(s, line, outcome)
        return None

    def _record(self, s: Session, line: _Line, t: int, reply: StepReply, overwrite: bool = True):
        """A progress answer for frame t: stitch point, frame record, window history."""
        p = float(reply.progress or 0.0)
        line.stitch.items.append(Point(t, p))
        fr = s.trace.frames[t]
        if overwrite or not fr.predicted:
            fr.subtask_path, fr.subtask_progress, fr.predicted = list(line.path), p, True
        desc = reply.description or line.last_description
        previous = line.history[-1].progress if line.history else line.first.progress
        if self.policy == "always" or p != previous:
            line.history.append(Seen(t, desc, p))
            if self.window is not None:  # the window shows at most window-2 of them
                del line.history[: -(self.window - 1)]
        line.last_progress = p
        line.end = point_value(line.base, line.scale, p)
        s.step(t, line.path, p, line.end)

    # -- prompts ---------------------------------------------------------------------------

    async def _step(self, s: Session, line: _Line, t: int) -> tuple[StepReply, bool]:
        can = self._can_decompose(line)
        system = render(
            "rover_system",
            task_description=line.subtask,
            decomposition=render("rover_decompose") if can else "",
        )
        content: list[TextPart | ImagePart] = []
        if t == line.first.position:  # c: task + first observation, nothing said yet
            shown = [t]
            await s.prefetch(shown)
            content += [text("Initial robot scene (current frame):"), s.image(t)]
        else:
            window = window_frames(line.first, line.history, self.window)
            shown = [w.position for w in window] + [t]
            await s.prefetch(shown)
            for i, w in enumerate(window):
                label = (
                    "Initial robot scene:"
                    if i == 0
                    else "Most recent previous frame:"
                    if i == len(window) - 1
                    else "Previous frame:"
                )
                content += [
                    text(label),
                    s.image(w.position),
                    text(
                        f"Frame description: {w.description or 'unavailable'}\n"
                        f"Subtask completion percentage: {pct(w.progress)}%"
                    ),
                ]
            content += [text("Current frame:"), s.image(t)]
        meta = s.meta(
            "rover.step",
            shown,
            subtask=line.subtask,
            subtask_path=list(line.path),
            extra={
                "line_id": line.id,
                "depth": line.depth,
                "allow_decompose": can,
                "completed": list(line.completed),
                "first_position": line.first.position,
            },
        )
        reminder = render(
            "rover_reminder",
            decompose_format="or\nFrame description: {}\nNew subtasks: [{}, {}, ...]\n"
            "The robot needs to: {}"
            if can
            else "",
        )
        line.node.calls += 1
        return await s.ask(
            system,
            content,
            meta,
            parse_step,
            lambda r: _plausible(r) or r.task_complete or (can and bool(r.new_subtask)),
            reminder,
            line_id=line.id,
        )

    async def _parent_turn(self, s: Session, line: _Line, child: _Line) -> tuple[StepReply, bool]:
        system = render(
            "rover_system",
            task_description=line.subtask,
            decomposition=render("rover_decompose"),
        )
        # ψ: the child's final frame and its final description
        f = child.last_position
        await s.prefetch([f])
        plan = "[" + ", ".join(f"'{p}'" for p in line.plan) + "]" if line.plan else "none given"
        body = render(
            "rover_parent",
            plan=plan,
            completed_subtask=child.subtask,
            final_description=child.last_description or "unavailable",
            completed_list="; ".join(line.completed),
            task_description=line.subtask,
        )
        before, _, after = body.partition("{image}")
        content: list[TextPart | ImagePart] = [
            text(before.rstrip("\n")),
            s.image(f),
            text(after.lstrip("\n")),
        ]
        meta = s.meta(
            "rover.parent",
            [f],
            subtask=line.subtask,
            subtask_path=list(line.path),
            extra={
                "line_id": line.id,
                "depth": line.depth,
                "completed": list(line.completed),
                "plan": list(line.plan),
                "at_position": f,
                "at_frame": s.frame_index(f),
            },
        )
        line.node.calls += 1
        return await s.ask(
            system,
            content,
            meta,
            parse_step,
            lambda r: r.usable_step,
            render("rover_parent_reminder"),
            line_id=line.id,
        )


class RoverNoWindow(Rover):
    """Ablation (App. M): recursion kept, the whole line of reasoning in context."""

    name = "rover-no-window"

    def __init__(self, **params: Any) -> None:
        params["window"] = None
        super().__init__(**params)


class RoverNoRecursion(Rover):
    """Ablation (App. M): the sliding window over the whole task, no subtasks."""

    name = "rover-no-recursion"

    def __init__(self, **params: Any) -> None:
        params["recursion"] = False
        super().__init__(**params)
