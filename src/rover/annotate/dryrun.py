"""`--dry-run`: how many calls and tokens an annotation would take, spending nothing.

The method runs for real on the real frames, but against a stand-in that answers every
prompt in the method's own format with progress rising evenly over the episode (the
oracle's answer builders on a straight-line truth) and prices each prompt with the
target backend's token rule. A real model that decomposes into subtasks makes a few more
ROVER calls (one per subtask switch), so the count is a floor for ROVER and exact for
methods whose calls do not depend on answers (GVL, the concat baselines).
"""

from __future__ import annotations

from dataclasses import dataclass

from rover.episode import Episode, GroundTruth
from rover.vlm.config import BackendConfig
from rover.vlm.loader import parse_spec
from rover.vlm.tokens import default_rule, estimate_usage
from rover.vlm.types import Completion, Prompt, SamplingParams


@dataclass
class DryRunTally:
    """Calls and estimated tokens, summed over every episode the dry run went through."""

    calls: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    image_tokens: int = 0

    @property
    def total_tokens(self) -> int:
        return self.prompt_tokens + self.completion_tokens


class DryRunVLM:
    """A VLM that answers for free and counts what the real backend would be asked."""

    def __init__(self, spec: str, config: BackendConfig, tally: DryRunTally | None = None) -> None:
        backend, model, _ = parse_spec(spec)
        self.backend, self.model = backend, model
        self.config = config
        self.rule = config.token_rule or default_rule(backend, config.detail)
        self.image_encoding = config.image_encoding()
        self.tally = tally or DryRunTally()
        self._answerer = None

    def bind(self, episode: Episode) -> DryRunVLM:
        from rover.vlm.oracle import BoundOracle

        bound = DryRunVLM.__new__(DryRunVLM)
        bound.__dict__.update(self.__dict__)
        n = episode.num_frames
        line = [i / max(n - 1, 1) for i in range(n)]
        plain = episode.model_copy(update={"truth": GroundTruth(progress=line)})
        bound._answerer = BoundOracle(plain, self.config)
        return bound

    async def complete(self, prompt: Prompt, params: SamplingParams | None = None) -> Completion:
        if self._answerer is None:
            raise RuntimeError("DryRunVLM must be bound to an episode first")
        text = self._answerer.answer(prompt.meta)
        usage = estimate_usage(prompt, text, self.rule)
        self.tally.calls += 1
        self.tally.prompt_tokens += usage.prompt_tokens
        self.tally.completion_tokens += usage.completion_tokens
        self.tally.image_tokens += usage.image_tokens
        return Completion(text=text, usage=usage, backend=self.backend, model=self.model)


async def estimate_annotation(opts, planned) -> DryRunTally:
    """Run the method over every pending episode against `DryRunVLM`; nothing is written."""
    import asyncio

    from rover.methods.registry import NON_VLM_METHODS, get_method

    tally = DryRunTally()
    if opts.method in NON_VLM_METHODS:
        return tally
    vlm = DryRunVLM(opts.backend, opts.backend_config, tally)
    params = {"window": opts.window, "seed": opts.seed}
    for _, episode_id in planned.pending:
        episode = await asyncio.to_thread(planned.reader.read, episode_id, opts.frames, opts.size)
        await get_method(opts.method, **params).run(episode, vlm)
    return tally
