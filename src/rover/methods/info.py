"""Method facts: what eval and report need to know about a method without running it.

One table, one place: the display name a figure shows, the colour every chart and the
viewer draw it in, whether it slides a window (and its default size), and whether it
calls a VLM (clip-value does not: no tokens, no calls). Eval asks these facts to build
variants; the report asks them to label and colour rows. Unknown methods (a user's own
class registered later) get a neutral fallback rather than an error, so an old run
directory still draws.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class MethodInfo:
    """The facts about one method that eval and report share."""

    name: str  # command-line name
    display: str  # name in tables and figures
    color: str  # hex colour, the same in every chart and the viewer
    windowed: bool = False  # behaviour depends on a sliding-window size (App. M)
    default_window: int | None = None
    calls_vlm: bool = True


_INFO = [
    MethodInfo("rover", "ROVER", "#1f77b4", windowed=True, default_window=3),
    MethodInfo("rover-no-window", "ROVER w/o window", "#17becf"),
    MethodInfo(
        "rover-no-recursion", "ROVER w/o recursion", "#9467bd", windowed=True, default_window=3
    ),
    MethodInfo("gvl", "GVL", "#d62728"),
    MethodInfo("gvl-single", "GVL (single call)", "#e377c2"),
    MethodInfo("temporal-concat", "TemporalConcat", "#2ca02c"),
    MethodInfo("local-concat", "LocalConcat", "#ff7f0e"),
    MethodInfo("video-concat", "VideoConcat", "#8c564b"),
    MethodInfo("clip-value", "CLIP value", "#7f7f7f", calls_vlm=False),
]
METHOD_INFO: dict[str, MethodInfo] = {m.name: m for m in _INFO}
METHOD_ORDER: list[str] = [m.name for m in _INFO]
# colours for methods the table does not know (a user's own), in order of appearance
_SPARE = ["#393b79", "#bcbd22", "#637939", "#8c6d31", "#e7969c", "#c5b0d5"]


def method_info(name: str) -> MethodInfo:
    """The facts about `name`; an unknown method gets its own name and a spare colour."""
    if name in METHOD_INFO:
        return METHOD_INFO[name]
    spare = _SPARE[sum(map(ord, name)) % len(_SPARE)]
    return MethodInfo(name, name, spare)


def display_name(name: str) -> str:
    return method_info(name).display


def method_rank(name: str) -> int:
    """Position in the paper's method order (unknown methods last)."""
    return METHOD_ORDER.index(name) if name in METHOD_ORDER else len(METHOD_ORDER)


WINDOW_METHODS = frozenset(m.name for m in _INFO if m.windowed)
NON_VLM_METHODS = frozenset(m.name for m in _INFO if not m.calls_vlm)
