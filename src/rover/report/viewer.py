"""The per-episode viewer: filmstrip, progress curves, reasoning tree, judged descriptions.

Produces plain data for the page template (which escapes every string it prints) plus
two kinds of markup built here: JPEG thumbnails written next to the page, and the
progress chart as inline SVG, whose only text (axis labels) is escaped on the way in.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from pathlib import Path

from PIL import Image

from rover.methods.trace import LineNode
from rover.report.run import RunData, TraceEntry

THUMB_SIDE = 112


@dataclass
class DescriptionRow:
    index: int
    progress: float | None
    predicted: bool
    subtask: str
    description: str
    verdict: str  # "true", "false", "inconclusive" or "" when not judged
    reason: str = ""


@dataclass
class TreeNode:
    subtask: str
    frames: str
    outcome: str
    final_description: str
    children: list[TreeNode] = field(default_factory=list)
    plan: list[str] = field(default_factory=list)  # subtasks the model announced, if any
    calls: int = 0


@dataclass
class MethodView:
    variant: str
    method: str
    color: str
    oracle: bool
    backend: str
    tokens: int
    calls: int
    rows: list[DescriptionRow]
    tree: TreeNode | None
    judged: bool


@dataclass
class EpisodeView:
    id: str
    task: str
    task_group: str
    level: int | None
    num_frames: int
    thumbs: list[tuple[int, str]]  # (original frame index, relative path)
    chart_svg: str  # trusted markup built by `progress_chart_svg`
    methods: list[MethodView]
    note: str = ""


def build_episode_views(
    run: RunData, out: Path, colors: dict[str, str], max_episodes: int = 40
) -> list[EpisodeView]:
    """One view per episode (at most `max_episodes`), thumbnails written under `out`."""
    by_episode: dict[str, list[TraceEntry]] = {}
    for e in run.entries:
        by_episode.setdefault(e.trace.episode_id, []).append(e)
    return [
        _episode_view(run, eid, by_episode[eid], out, colors)
        for eid in sorted(by_episode)[:max_episodes]
    ]


def _episode_view(
    run: RunData, eid: str, entries: list[TraceEntry], out: Path, colors: dict[str, str]
) -> EpisodeView:
    episode = run.episodes.get(eid)
    traces = [e.trace for e in entries]
    indices = sorted({f.index for t in traces for f in t.frames})
    thumbs: list[tuple[int, str]] = []
    note = ""
    with_frames = run.episode_frames(eid, traces[0].view)
    if with_frames is not None:
        thumbs = _write_thumbs(with_frames.frames(), with_frames.frame_indices, indices, out, eid)
    else:
        note = "frames unavailable (dataset not found)"
    truth: list[tuple[int, float]] = []
    if episode is not None and episode.truth is not None:
        truth = [
            (ix, p * 100)
            for ix, p in zip(episode.frame_indices, episode.truth.progress, strict=True)
        ]
    methods = []
    curves = []
    for entry in entries:
        t, variant = entry.trace, entry.label
        color = colors.get(variant, "#555555")
        verdicts = run.verdicts.get(entry.key, {})
        rows = [
            DescriptionRow(
                index=f.index,
                progress=f.progress,
                predicted=f.predicted,
                subtask=" › ".join(f.subtask_path),
                description=f.description or "",
                verdict=verdicts[f.index].verdict if f.index in verdicts else "",
                reason=verdicts[f.index].reason if f.index in verdicts else "",
            )
            for f in t.frames
        ]
        totals = t.totals if t.totals.calls or not t.calls else t.compute_totals()
        methods.append(
            MethodView(
                variant=variant,
                method=t.method,
                color=color,
                oracle=t.oracle or t.backend == "oracle",
                backend=f"{t.backend}:{t.model}" if t.model else t.backend,
                tokens=totals.total_tokens,
                calls=totals.calls,
                rows=rows,
                tree=_tree(t.tree) if t.tree is not None else None,
                judged=bool(verdicts),
            )
        )
        curves.append((variant, color, [(f.index, f.progress or 0.0) for f in t.frames]))
    return EpisodeView(
        id=eid,
        task=episode.task if episode else traces[0].task,
        task_group=(episode.task_group if episode else None) or "",
        level=episode.truth.level if episode and episode.truth else None,
        num_frames=len(indices),
        thumbs=thumbs,
        chart_svg=progress_chart_svg(truth, curves),
        methods=methods,
        note=note,
    )


def _tree(node: LineNode) -> TreeNode:
    last = "…" if node.last_frame is None else str(node.last_frame)
    return TreeNode(
        subtask=node.subtask,
        frames=f"frames {node.first_frame}–{last}",
        outcome=node.outcome.replace("_", " "),
        final_description=node.final_description or "",
        children=[_tree(c) for c in node.children],
        plan=list(getattr(node, "planned_subtasks", []) or []),
        calls=int(getattr(node, "calls", 0) or 0),
    )


def _write_thumbs(
    frames, frame_indices: list[int], wanted: list[int], out: Path, eid: str
) -> list[tuple[int, str]]:
    folder = out / "frames" / _safe(eid)
    folder.mkdir(parents=True, exist_ok=True)
    pos_of = {ix: p for p, ix in enumerate(frame_indices)}
    thumbs = []
    for ix in wanted or frame_indices:
        if ix not in pos_of:
            continue
        path = folder / f"{ix:05d}.jpg"
        if not path.exists():
            img = Image.fromarray(frames[pos_of[ix]])
            img.thumbnail((THUMB_SIDE, THUMB_SIDE))
            img.save(path, format="JPEG", quality=80)
        thumbs.append((ix, path.relative_to(out).as_posix()))
    return thumbs


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "episode"


def progress_chart_svg(
    truth: list[tuple[int, float]],
    curves: list[tuple[str, str, list[tuple[int, float]]]],
    width: int = 640,
    height: int = 240,
) -> str:
    """Ground truth (dashed black) against each method's progress, as inline SVG markup."""
    left, right, top, bottom = 40, 10, 10, 28
    xs = [x for x, _ in truth] + [x for _, _, pts in curves for x, _ in pts]
    x0, x1 = (min(xs), max(xs)) if xs else (0, 1)
    x1 = x1 if x1 > x0 else x0 + 1
    pw, ph = width - left - right, height - top - bottom

    def sx(x: float) -> float:
        return left + (x - x0) / (x1 - x0) * pw

    def sy(y: float) -> float:
        return top + (1 - max(0.0, min(100.0, y)) / 100) * ph

    parts = [
        f'<svg class="chart" viewBox="0 0 {width} {height}" width="{width}" '
        f'height="{height}" role="img" aria-label="progress per frame">'
    ]
    for y in (0, 25, 50, 75, 100):
        parts.append(
            f'<line x1="{left}" x2="{width - right}" y1="{sy(y):.1f}" y2="{sy(y):.1f}" '
            f'stroke="#ddd" stroke-width="1"/>'
        )
        parts.append(
            f'<text x="{left - 6}" y="{sy(y) + 4:.1f}" text-anchor="end" '
            f'font-size="11" fill="#555">{y}</text>'
        )
    for x in _ticks(x0, x1):
        parts.append(
            f'<text x="{sx(x):.1f}" y="{height - 10}" text-anchor="middle" '
            f'font-size="11" fill="#555">{x}</text>'
        )
    for name, color, pts in reversed(curves):  # the first method (ROVER) drawn on top
        parts.append(_polyline(pts, sx, sy, html.escape(color, quote=True), 1.8, "", name))
    if truth:
        parts.append(
            _polyline(truth, sx, sy, "#000", 2.6, ' stroke-dasharray="6 4"', "ground truth")
        )
    parts.append("</svg>")
    return "".join(parts)


def _polyline(pts, sx, sy, color: str, width: float, extra: str, name: str) -> str:
    coords = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in pts)
    return (
        f'<polyline fill="none" stroke="{color}" stroke-width="{width}"{extra} '
        f'points="{coords}"><title>{html.escape(name)}</title></polyline>'
    )


def _ticks(x0: int, x1: int, n: int = 8) -> list[int]:
    step = max(1, round((x1 - x0) / n))
    return list(range(x0, x1 + 1, step))
