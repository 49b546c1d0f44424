"""The per-episode viewer: filmstrip, progress curves, reasoning tree, judged descriptions.

Each episode is its own small page, `episodes/<episode>.html`, beside the main page,
which lists every episode with its scores and shows one at a time in a frame: the main
page stays small however many episodes a run has, and it all works from `file://`
(no fetch, no server). Produces plain data for the templates (which escape every
string they print) plus the progress chart as inline SVG, built here from numbers, whose
only text (axis labels, tick numbers) is escaped on the way in.
"""

from __future__ import annotations

import html
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path

from rover.methods.trace import LineNode
from rover.report.run import RunData, TraceEntry
from rover.report.scores import EpisodeScore


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
    plan: list[str] = field(default_factory=list)
    calls: int = 0


@dataclass
class MethodView:
    variant: str
    method: str
    color: str
    view: str
    backend: str
    tokens: int
    calls: int
    rows: list[DescriptionRow]
    tree: TreeNode | None
    judged: bool
    score: EpisodeScore | None = None


@dataclass
class EpisodeView:
    id: str
    slug: str  # file stem of its page, episodes/<slug>.html
    task: str
    task_group: str
    level: int | None
    dataset: str | None
    num_frames: int
    truth_kind: str  # "simulation", "frame_number", ... or "" without truth
    thumbs: list[tuple[int, str]]  # (original frame index, path relative to the episode page)
    chart_svg: str  # trusted markup built by `progress_chart_svg`
    methods: list[MethodView]
    spread: float | None = None  # how much the methods disagree (Pearson max - min)
    note: str = ""


def build_episode_views(
    run: RunData, out: Path, colors: dict[str, str], scores: list[EpisodeScore]
) -> list[EpisodeView]:
    """One view per episode, frames copied under `out/frames`; most informative first."""
    by_episode: dict[str, list[TraceEntry]] = {}
    for e in run.entries:
        by_episode.setdefault(e.trace.episode_id, []).append(e)
    score_of = {(s.variant_id, s.episode_id): s for s in scores}
    views = [_episode_view(run, eid, es, out, colors, score_of) for eid, es in by_episode.items()]
    return sorted(views, key=lambda v: (-(v.spread if v.spread is not None else -1.0), v.id))


def _spread(values: list[float | None]) -> float | None:
    vals = [v for v in values if v is not None]
    return max(vals) - min(vals) if len(vals) > 1 else None


def _episode_view(
    run: RunData,
    eid: str,
    entries: list[TraceEntry],
    out: Path,
    colors: dict[str, str],
    score_of: dict[tuple[str, str], EpisodeScore],
) -> EpisodeView:
    episode = run.episodes.get(eid)
    traces = [e.trace for e in entries]
    slug = _safe(eid)
    indices = sorted({f.index for t in traces for f in t.frames})
    saved = run.thumbs(eid, entries[0].view or traces[0].view)
    thumbs = []
    # a report inside its run (the default) points at the run's frames; one written
    # elsewhere gets its own copies, so it can be moved on its own
    inside = out.resolve().is_relative_to(run.run_dir.resolve())
    for ix in indices or sorted(saved):
        if ix not in saved:
            continue
        if inside:
            thumbs.append((ix, os.path.relpath(saved[ix], out / "episodes")))
            continue
        dest = out / "frames" / slug / saved[ix].name
        if not dest.exists():
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(saved[ix], dest)
        thumbs.append((ix, f"../frames/{slug}/{dest.name}"))
    note = "" if thumbs else "frames unavailable: this run kept no frames for the episode"
    truth: list[tuple[int, float]] = []
    if episode is not None and episode.truth is not None:
        truth = [
            (ix, p * 100)
            for ix, p in zip(episode.frame_indices, episode.truth.progress, strict=True)
        ]
    methods, curves = [], []
    for entry in entries:
        t = entry.trace
        color = colors.get(entry.label, "#555555")
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
        score = score_of.get(entry.key)
        methods.append(
            MethodView(
                variant=entry.label,
                method=t.method,
                color=color,
                view=entry.view,
                backend=f"{t.backend}:{t.model}" if t.model else t.backend,
                tokens=score.tokens if score else t.totals.total_tokens,
                calls=score.calls if score else t.totals.calls,
                rows=rows,
                tree=_tree(t.tree) if t.tree is not None else None,
                judged=bool(verdicts),
                score=score,
            )
        )
        curves.append((entry.label, color, [(f.index, f.progress or 0.0) for f in t.frames]))
    return EpisodeView(
        id=eid,
        slug=slug,
        task=episode.task if episode else traces[0].task,
        task_group=(episode.task_group if episode else None) or "",
        level=episode.truth.level if episode and episode.truth else None,
        dataset=entries[0].row.get("dataset"),
        num_frames=len(indices),
        truth_kind=episode.truth.progress_source if episode and episode.truth else "",
        thumbs=thumbs,
        chart_svg=progress_chart_svg(truth, curves),
        methods=methods,
        spread=_spread([m.score.pearson if m.score else None for m in methods]),
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


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "episode"


def progress_chart_svg(
    truth: list[tuple[int, float]],
    curves: list[tuple[str, str, list[tuple[int, float]]]],
    width: int = 640,
    height: int = 260,
) -> str:
    """Ground truth (dashed black) against each method's progress, as inline SVG markup.

    Curve i carries class `curve-i`, so the page's legend checkboxes can hide it (CSS only).
    """
    left, right, top, bottom = 52, 10, 10, 44
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
            f'<text x="{sx(x):.1f}" y="{top + ph + 16}" text-anchor="middle" '
            f'font-size="11" fill="#555">{x}</text>'
        )
    parts.append(
        f'<text x="{left + pw / 2:.1f}" y="{height - 6}" text-anchor="middle" font-size="12" '
        f'fill="#333">frame index (original video)</text>'
    )
    parts.append(
        f'<text x="14" y="{top + ph / 2:.1f}" text-anchor="middle" font-size="12" fill="#333" '
        f'transform="rotate(-90 14 {top + ph / 2:.1f})">task progress (%)</text>'
    )
    for i, (name, color, pts) in reversed(list(enumerate(curves))):  # first drawn on top
        parts.append(
            _polyline(pts, sx, sy, html.escape(color, quote=True), 1.8, "", name, f"curve-{i}")
        )
    if truth:
        parts.append(
            _polyline(
                truth, sx, sy, "#000", 2.6, ' stroke-dasharray="6 4"', "ground truth", "truth"
            )
        )
    parts.append("</svg>")
    return "".join(parts)


def _polyline(pts, sx, sy, color: str, width: float, extra: str, name: str, cls: str) -> str:
    coords = " ".join(f"{sx(x):.1f},{sy(y):.1f}" for x, y in pts)
    return (
        f'<polyline class="{cls}" fill="none" stroke="{color}" stroke-width="{width}"{extra} '
        f'points="{coords}"><title>{html.escape(name)}</title></polyline>'
    )


def _ticks(x0: int, x1: int, n: int = 8) -> list[int]:
    step = max(1, round((x1 - x0) / n))
    return list(range(x0, x1 + 1, step))
