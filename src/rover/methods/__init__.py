"""Reasoning methods: ROVER, its ablations and the baselines, each Episode + VLM -> Trace.

Prompt kinds (`PromptMeta.kind`) used here, which the oracle backend answers:
"rover.step" (one ROVER step on a window of frames), "rover.parent" (the parent turn
after a child line returns, showing the child's final frame), "gvl.batch" (shuffled frames
with a 0% anchor), "concat.frame" (ordered frames, answer for the last one) and
"concat.video" (every frame). A re-ask with a format reminder keeps the kind and sets
`meta.extra["reminder"] = True` (and `meta.extra["missing"]`, the frame labels a cut-off
reply did not reach).
"""

from rover.methods.base import Method, StepInfo
from rover.methods.registry import get_method, method_names
from rover.methods.trace import CallRecord, FrameRecord, LineNode, Totals, Trace

__all__ = [
    "CallRecord",
    "FrameRecord",
    "LineNode",
    "Method",
    "StepInfo",
    "Totals",
    "Trace",
    "get_method",
    "method_names",
]
