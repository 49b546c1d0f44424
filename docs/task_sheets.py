"""Contact sheets and progress plots of a generated dataset, one of each per task.

Usage: python docs/task_sheets.py [--dataset DIR] [--tasks Lift,Door] [--out docs/images]

Without ``--dataset`` (or when DIR does not exist yet) it first generates one: every
level, one video each, views wrist, left and right, 128 px, seed 0. Then, per task:

- ``task_<task>.png``: rows = (lowest level, highest level) x each view, columns = the
  start, middle and end frame of that video;
- ``progress_<task>.png``: ground-truth progress of every video over normalised time,
  one colour per level, each frame's state type marked (expert, non-expert,
  interpolating) so recoveries and final deviations show; the frames of the grasp (g),
  drop (d) and place (p) events written on each curve; for an articulated task, the
  top level's joint (fraction of the way to its goal) dashed, so progress can be
  checked against the knob's turn or the drawer's slide.
"""

from __future__ import annotations

import argparse
from collections import defaultdict
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from rover.episode import Episode, StateType
from rover.io.dataset import load_dataset

EVENT_MARK = {"grasp": "g", "drop": "d", "place": "p"}
TYPE_MARK = {
    StateType.expert: ("o", "#4c72b0", "expert"),
    StateType.non_expert: ("x", "#c44e52", "non-expert"),
    StateType.interpolating: ("^", "#dd8452", "interpolating"),
}


def _generate(root: Path, tasks: list[str]) -> None:
    from rover.sim.generate import GenerateConfig, generate

    cfg = GenerateConfig(
        tasks=tasks, per_level=1, views=["wrist", "left", "right"], size=128, seed=0
    )
    generate(cfg, root, workers=2)


def _label(img: np.ndarray, text: str) -> np.ndarray:
    pic = Image.fromarray(img)
    ImageDraw.Draw(pic).text((3, 2), text, fill=(255, 255, 0))
    return np.asarray(pic)


def contact_sheet(low: Episode, high: Episode) -> np.ndarray:
    """Rows: each view of the lowest then the highest level; columns: start, middle, end."""
    rows = []
    for ep in (low, high):
        n = ep.num_frames
        for view in ep.view_names:
            frames = ep.frames(view)
            cells = [
                _label(frames[t], f"L{ep.truth.level} {view} t={t}" if ep.truth else view)
                for t in (0, n // 2, n - 1)
            ]
            rows.append(np.concatenate(cells, axis=1))
    return np.concatenate(rows, axis=0)


def progress_plot(task: str, episodes: list[Episode], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    levels = sorted({e.truth.level for e in episodes if e.truth and e.truth.level})
    cmap = plt.get_cmap("viridis", max(len(levels), 2))
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=100)
    seen: set[str] = set()
    for ep in sorted(episodes, key=lambda e: e.truth.level or 0):
        tr = ep.truth
        x = np.linspace(0, 1, ep.num_frames)
        colour = cmap(levels.index(tr.level))
        ax.plot(x, tr.progress, color=colour, lw=1.4, label=f"L{tr.level}")
        for st, (mark, c, name) in TYPE_MARK.items():
            idx = [t for t, s in enumerate(tr.state_type or []) if s == st]
            if st == StateType.expert or not idx:
                continue
            lab = None if name in seen else name
            seen.add(name)
            ax.scatter(x[idx], np.asarray(tr.progress)[idx], marker=mark, c=c, s=14, label=lab)
        for ev in tr.events:
            if ev.name in EVENT_MARK and ev.frame is not None:
                t = ev.frame
                ax.annotate(
                    EVENT_MARK[ev.name],
                    (x[t], tr.progress[t]),
                    xytext=(0, 5),
                    textcoords="offset points",
                    fontsize=7,
                    color=colour,
                    ha="center",
                )
    top = max(episodes, key=lambda e: (e.truth.level or 0, e.id))
    for name, way in _joint_ways(top).items():
        x = np.linspace(0, 1, top.num_frames)
        ax.plot(x, way, color="0.35", lw=1.0, ls="--", label=f"{name} (L{top.truth.level})")
    handles, labels = ax.get_legend_handles_labels()
    uniq = dict(zip(labels, handles, strict=False))
    ax.legend(uniq.values(), uniq.keys(), fontsize=7, ncol=2, loc="upper left")
    ax.set(xlabel="normalised time", ylabel="progress", ylim=(-0.02, 1.05), title=task)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _joint_ways(ep: Episode) -> dict[str, list[float]]:
    """Each articulated part's fraction of the way to its goal per frame (a part starting
    past half way, an open drawer to close, counts down from 1)."""
    facts = ep.truth.facts if ep.truth else None
    if not facts or not facts[0].articulations:
        return {}
    out = {}
    for name, first in facts[0].articulations.items():
        vals = [f.articulations.get(name, first) for f in facts]
        out[name] = [1.0 - v if first > 0.5 else v for v in vals]
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--dataset", type=Path, default=Path("data/task_sheets"))
    ap.add_argument("--tasks", default=None, help="comma-separated (default: every task)")
    ap.add_argument("--out", type=Path, default=Path("docs/images"))
    args = ap.parse_args()
    from rover.sim.tasks import task_names

    tasks = args.tasks.split(",") if args.tasks else task_names()
    if not (args.dataset / "dataset.json").exists():
        _generate(args.dataset, tasks)
    by_task: dict[str, list[Episode]] = defaultdict(list)
    for ep in load_dataset(args.dataset):
        task = str(ep.extra.get("sim_task", ep.task))
        if task in tasks:
            by_task[task].append(ep)
    args.out.mkdir(parents=True, exist_ok=True)
    for task, eps in by_task.items():
        eps.sort(key=lambda e: (e.truth.level, e.id))
        sheet = args.out / f"task_{task}.png"
        Image.fromarray(contact_sheet(eps[0], eps[-1])).save(sheet, optimize=True)
        plot = args.out / f"progress_{task}.png"
        progress_plot(task, eps, plot)
        print(f"{sheet}  {plot}")


if __name__ == "__main__":
    main()
