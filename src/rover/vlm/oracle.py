"""The oracle backend: answers every method's prompts from the episode's ground truth.

It reads no pixels. It exists for the offline demo, tests and upper-bound analysis, and
everything it produces is labelled as oracle output (`Trace.oracle`). The answer it gives
depends on what the prompt asks (`PromptMeta.kind`), in exactly the format the method's
prompt requests:

- "rover.step" at the root line: decomposes like a model that knows the task, from the
  task's full subtask list (the simulator task spec's, not only the subtasks this attempt
  reached): "New subtasks: [...]" then "The robot needs to: <first>";
  inside a subtask line: that subtask's progress, ground-truth progress rescaled to the
  subtask's span (0% at the frame the previous subtask ended, 100% at its own end).
  Without subtasks (or when decomposition is not allowed) it reports full-task progress.
- "rover.parent": the next ground-truth subtask, or "Task complete".
- "gvl.batch", "concat.video": every labelled frame's full-task progress; "concat.frame":
  the last frame's.

Frame descriptions are sentences built from `FrameFacts` in the vocabulary the rule judge
understands ("The gripper is open.", "The robot is holding the can.", ...). Noise knobs
from `BackendConfig`: `flip_prob` flips each claim of a description with that probability
(perception errors), `jitter` adds gaussian noise (percentage points) to every progress
value. Noise is a pure function of (seed, frame, question), so runs are reproducible and
independent of call order.

Like a real model it honours `max_tokens`: a longer answer is cut at that many tokens
(counted as the usage estimate counts them) and reported with finish reason "length", so
tests and the demo see truncation. A re-ask that names `meta.extra["missing"]` frames is
answered for those frames only.
"""

from __future__ import annotations

import zlib
from typing import TYPE_CHECKING

import numpy as np

from rover.errors import BackendError, InputError
from rover.vlm.base import BaseBackend, RawAnswer
from rover.vlm.config import BackendConfig
from rover.vlm.tokens import estimate_text_tokens
from rover.vlm.types import Prompt, PromptMeta, SamplingParams

if TYPE_CHECKING:
    from rover.episode import Episode, FrameFacts, GroundTruth


def _rng(seed: int, *key: object) -> np.random.Generator:
    h = zlib.crc32("|".join(map(str, key)).encode())
    return np.random.default_rng([int(seed) & 0xFFFFFFFF, h])


def _the(name: str) -> str:
    return name if name.lower().startswith(("the ", "a ", "bin ", "drawer ")) else f"the {name}"


def describe(facts: FrameFacts | None, flip_prob: float = 0.0, rng=None) -> str:
    """Sentences stating the frame's facts; each claim flipped with `flip_prob`."""
    if facts is None:
        return "The robot is working on the task."
    rng = rng or np.random.default_rng(0)

    def flip() -> bool:
        return flip_prob > 0 and bool(rng.random() < flip_prob)

    out: list[str] = []
    gripper = facts.gripper
    if flip():
        gripper = "closed" if gripper == "open" else "open"
    out.append(f"The gripper is {gripper}.")
    for obj in facts.contacts:
        neg = " not" if flip() else ""
        out.append(f"The gripper is{neg} touching {_the(obj)}.")
    known = list(facts.objects) or list(facts.contacts)
    if facts.holding:
        out.append(
            "The robot is not holding anything."
            if flip()
            else f"The robot is holding {_the(facts.holding)}."
        )
    elif flip() and known:
        out.append(f"The robot is holding {_the(known[0])}.")
    else:
        out.append("The robot is not holding anything.")
    for name, obj in facts.objects.items():
        thing = _the(name).capitalize()
        if obj.inside:
            out.append(f"{thing} is{' not' if flip() else ''} in {obj.inside}.")
        elif obj.lifted:
            out.append(f"{thing} is on the table." if flip() else f"{thing} is lifted.")
        elif obj.on:
            out.append(f"{thing} is lifted." if flip() else f"{thing} is on {_the(obj.on)}.")
    for part, frac in facts.articulations.items():
        if part in ("button", "stop button") or part in facts.pressed:  # on/off, said below
            continue
        if flip():
            frac = 1.0 - frac
        out.append(f"{_the(part).capitalize()} is {round(100 * frac)}% open.")
    for part in sorted(set(facts.pressed) | ({"button", "stop button"} & set(facts.articulations))):
        pressed = part in facts.pressed or facts.articulations.get(part, 0.0) >= 0.5
        if flip():
            pressed = not pressed
        out.append(f"{_the(part).capitalize()} is {'pressed' if pressed else 'not pressed'}.")
    return " ".join(out)


def subtask_progress(truth: GroundTruth, j: int, pos: int, planned: int | None = None) -> float:
    """Subtask j's progress at `pos` (0..100): truth rescaled to the subtask's span.

    0% at the frame the previous subtask ended (where ROVER's child line starts), 100% at
    the subtask's own end. When the video ends inside the subtask with the task unfinished,
    its end is not a completion: the subtask's nominal share of the rest of the plan
    (`planned` subtasks in all, default: those the attempt reached) is used instead.
    """
    prog, subs = truth.progress, truth.subtasks
    s = subs[j]
    lo = prog[s.start - 1] if s.start > 0 else prog[0]
    hi = prog[min(s.end, len(prog) - 1)]
    last = len(prog) - 1
    if s.end >= last and prog[last] < 0.999:
        hi = lo + (1.0 - lo) / max((planned or len(subs)) - j, 1)
    if hi - lo < 1e-9:
        return 100.0 if pos >= s.end else 0.0
    return 100.0 * (prog[pos] - lo) / (hi - lo)


def _fmt(p: float) -> str:
    return str(int(round(p)))


def task_plan(episode: Episode) -> list[str]:
    """The task's full subtask list, as a model that knows the task would plan it.

    Simulated episodes name their task spec (`extra["sim_task"]`); its subtasks are the
    plan. Elsewhere (or when the spec's names do not cover the attempt's) the subtasks in
    the ground truth are used.
    """
    reached = [s.name for s in (episode.truth.subtasks if episode.truth else [])]
    name = episode.extra.get("sim_task") if isinstance(episode.extra, dict) else None
    if name:
        try:  # task specs are plain data; imported only for simulated episodes
            from rover.sim.tasks import get_task

            plan = [s.name for s in get_task(str(name)).subtasks]
        except Exception:  # noqa: BLE001 - an unknown or unloadable spec: use the truth
            plan = []
        if plan and reached == plan[: len(reached)]:
            return plan
    return reached


def truncate_tokens(text: str, max_tokens: int) -> tuple[str, bool]:
    """`text` cut to at most `max_tokens` tokens (as estimated), and whether it was cut."""
    if estimate_text_tokens(text) <= max_tokens:
        return text, False
    lo, hi = 0, len(text)  # longest prefix within the budget: binary search on characters
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if estimate_text_tokens(text[:mid]) <= max_tokens:
            lo = mid
        else:
            hi = mid - 1
    return text[:lo], True


def require_simulator_truth(episode: Episode) -> None:
    """The one rule for the oracle on real data: it answers only from simulator truth.

    Every method and `rover eval` bind the oracle to an episode before asking it anything,
    so refusing here covers `rover reason`, `rover eval` and `rover annotate` alike. Real
    videos carry no truth, or App. L's frame-number stand-in, which the oracle would echo
    back as a perfect score.
    """
    truth = episode.truth
    if truth is None or truth.progress_source != "simulation":
        what = "no ground truth" if truth is None else f"{truth.progress_source} progress only"
        raise InputError(
            f"the oracle answers from simulator ground truth; episode {episode.id!r} has "
            f"{what}: use a real backend (openai:, gemini:, hf:) or replay:"
        )


class OracleBackend(BaseBackend):
    """Unbound oracle: `bind(episode)` gives the instance that actually answers."""

    backend = "oracle"
    use_cache = False

    def __init__(self, config: BackendConfig | None = None, model: str = "ground-truth") -> None:
        super().__init__(model, config)

    @property
    def spec(self) -> str:
        return "oracle"

    def bind(self, episode: Episode) -> BoundOracle:
        return BoundOracle(episode, self.config)

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        raise BackendError(
            "the oracle backend must be bound to an episode first (vlm.bind(episode))"
        )


class BoundOracle(OracleBackend):
    """The oracle for one episode: answers from `episode.truth`."""

    def __init__(self, episode: Episode, config: BackendConfig | None = None) -> None:
        super().__init__(config)
        require_simulator_truth(episode)
        self.episode = episode
        self.plan = task_plan(episode)
        self._descriptions: dict[int, str] = {}  # deterministic per frame: compute once

    def bind(self, episode: Episode) -> BoundOracle:
        return self if episode is self.episode else BoundOracle(episode, self.config)

    async def _generate(self, prompt: Prompt, params: SamplingParams) -> RawAnswer:
        text, cut = truncate_tokens(self.answer(prompt.meta), params.max_tokens)
        return RawAnswer(text=text, finish_reason="length" if cut else "stop", truncated=cut)

    # -- answers ---------------------------------------------------------------------------

    def _truth(self) -> GroundTruth:
        truth = self.episode.truth
        if truth is None:
            raise BackendError(
                "the oracle backend answers from simulator ground truth; episode "
                f"{self.episode.id!r} has none — use a real backend or replay"
            )
        return truth

    def answer(self, meta: PromptMeta) -> str:
        """The reply text for a prompt described by `meta` (no pixels involved)."""
        truth = self._truth()
        kind = meta.kind.removesuffix(".reminder")
        if kind == "rover.step":
            return self._rover_step(truth, meta)
        if kind == "rover.parent":
            return self._rover_parent(truth, meta)
        if kind in ("gvl.batch", "concat.video"):
            return self._frames(truth, meta)
        if kind == "concat.frame":
            pos = self._positions(meta)[-1]
            return self._frame_block(truth, pos, meta.kind, None)
        raise BackendError(f"the oracle backend cannot answer prompts of kind {meta.kind!r}")

    def _positions(self, meta: PromptMeta) -> list[int]:
        if meta.positions:
            return list(meta.positions)
        index = {f: p for p, f in enumerate(self.episode.frame_indices)}
        try:
            return [index[f] for f in meta.frame_indices]
        except KeyError as exc:
            raise BackendError(f"oracle: frame {exc} is not in episode {self.episode.id}") from exc

    def _desc(self, truth: GroundTruth, pos: int) -> str:
        hit = self._descriptions.get(pos)
        if hit is None:
            facts = truth.facts[pos] if truth.facts is not None else None
            rng = _rng(self.config.seed, "desc", pos)
            hit = self._descriptions[pos] = describe(facts, self.config.flip_prob, rng)
        return hit

    def _noisy(self, p: float, *key: object) -> float:
        if self.config.jitter > 0:
            p += float(_rng(self.config.seed, "jitter", *key).normal(0.0, self.config.jitter))
        return p

    def _full(self, truth: GroundTruth, pos: int, kind: str) -> float:
        return self._noisy(100.0 * truth.progress[pos], kind, pos)

    def _frame_block(self, truth: GroundTruth, pos: int, kind: str, label: int | None) -> str:
        head = "" if label is None else f"Frame {label}:\n"
        return (
            f"{head}Frame description: {self._desc(truth, pos)}\n"
            f"Task completion percentage: {_fmt(self._full(truth, pos, kind))}%"
        )

    def _frames(self, truth: GroundTruth, meta: PromptMeta) -> str:
        positions = self._positions(meta)
        labels = meta.extra.get("labels") or list(range(len(positions)))
        wanted = set(meta.extra.get("missing") or labels)  # a re-ask after a cut-off reply
        blocks = [
            self._frame_block(truth, pos, meta.kind, label)
            for pos, label in zip(positions, labels, strict=False)
            if label is not None and label in wanted
        ]
        return "\n\n".join(blocks)

    def _subtask_index(self, truth: GroundTruth, name: str, first: int) -> int | None:
        matches = [j for j, s in enumerate(truth.subtasks) if s.name == name]
        if not matches:
            return None
        return min(matches, key=lambda j: abs(max(truth.subtasks[j].start - 1, 0) - first))

    def _rover_step(self, truth: GroundTruth, meta: PromptMeta) -> str:
        pos = self._positions(meta)[-1]
        desc = self._desc(truth, pos)
        plan = self.plan
        allow = bool(meta.extra.get("allow_decompose", True))
        if not meta.subtask_path:
            done = len(meta.extra.get("completed", []))
            if allow and plan and done < len(plan):
                text = f"Frame description: {desc}\n"
                if done == 0 and len(plan) > 1:
                    text += "New subtasks: [" + ", ".join(f"'{s}'" for s in plan) + "]\n"
                return text + f"The robot needs to: {plan[done]}"
            p = self._full(truth, pos, "rover")
        else:
            j = self._subtask_index(
                truth, meta.subtask_path[-1], int(meta.extra.get("first_position", pos))
            )
            if j is None:
                p = self._full(truth, pos, "rover")
            else:
                planned = len(self.plan) if self.plan else None
                p = self._noisy(subtask_progress(truth, j, pos, planned), "rover", pos, j)
        return f"Frame description: {desc}\nSubtask completion percentage: {_fmt(p)}%\n[next-frame]"

    def _rover_parent(self, truth: GroundTruth, meta: PromptMeta) -> str:
        done = len(meta.extra.get("completed", []))
        if not meta.subtask_path and done < len(self.plan):
            return f"The robot needs to: {self.plan[done]}"
        return "Task complete"
