"""Where an evaluation's episodes come from, and the per-variant view of each episode.

Two kinds of input: a rover dataset directory (`--dataset`) and any source spec
(`--source lerobot:PATH,rlds:PATH`, App. L). Loading decodes only the views and frames
the run's variants need; `variant_episode` then picks each variant's frames by *original
frame index*, so a 30-frame variant sees exactly `Episode.subsample(30)` of the episode
as stored, whatever other frame counts the same run sweeps.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rover.episode import Episode, even_positions
from rover.errors import InputError
from rover.eval.variants import Variant
from rover.io.dataset import episode_ids, read_dataset_info, read_episode
from rover.io.video import read_video


@dataclass
class EpisodeRef:
    """One episode to evaluate: a run-unique id, where it lives, which dataset it is from."""

    id: str  # unique within the run (prefixed by the source label when several sources)
    source_id: str  # the id inside its source
    dataset: str  # label for per-dataset tables
    origin: str  # dataset directory or source spec


def _sample(ids: list[str], n: int | None, seed: int) -> list[str]:
    from rover.io.source import sample_episode_ids

    class _Ids:
        def episode_ids(self) -> list[str]:
            return ids

    return sample_episode_ids(_Ids(), n, seed)  # type: ignore[arg-type]


def dataset_refs(root: Path, n: int | None, seed: int) -> list[EpisodeRef]:
    root = Path(root)
    if not root.exists():
        raise InputError(f"--dataset {root}: no such directory")
    info = read_dataset_info(root)
    ids = episode_ids(root)
    if not ids:
        raise InputError(f"--dataset {root}: no complete episodes under {root / 'episodes'}")
    return [EpisodeRef(i, i, info.name, str(root)) for i in _sample(ids, n, seed)]


def source_refs(specs: list[str], n: int | None, seed: int) -> list[EpisodeRef]:
    from rover.io.source import open_source, require_tasks

    refs: list[EpisodeRef] = []
    labels: dict[str, str] = {}
    for spec in specs:
        reader = open_source(spec)
        label = reader.dataset  # the builder / dataset name, not a version folder's
        if label in labels:
            raise InputError(
                f"--source: {labels[label]} and {spec} are both dataset {label!r}; "
                "give each dataset once (their traces would overwrite each other)"
            )
        labels[label] = spec
        ids = reader.episode_ids()
        if not ids:
            raise InputError(f"--source {spec}: no episodes found")
        picked = _sample(ids, n, seed)
        require_tasks(reader, picked, where=f"--source {spec}")
        prefix = f"{label}__" if len(specs) > 1 else ""
        refs += [EpisodeRef(prefix + i, i, label, spec) for i in picked]
    return refs


def needed_views(variants: list[Variant]) -> list[str | None]:
    return list(dict.fromkeys(v.view for v in variants))


def is_real_source(origin: str) -> bool:
    """True for recorded data (LeRobot, RLDS, HDF5, videos, frame folders), False for a
    rover dataset directory, whose episodes carry the simulator's ground truth."""
    return origin.startswith(("lerobot:", "rlds:", "hdf5:")) or not (
        (Path(origin) / "dataset.json").exists()
    )


def load_for_variants(ref: EpisodeRef, variants: list[Variant]) -> tuple[Episode, Episode]:
    """(metadata of the whole episode, episode with the pixels the variants need).

    Blocking (decodes video): call through `asyncio.to_thread`.
    """
    if is_real_source(ref.origin):
        return _load_from_source(ref, variants)
    root = Path(ref.origin)
    meta = read_episode(root, ref.source_id, load_frames=False)
    views = {v or meta.view for v in needed_views(variants)}
    for v in views:
        if v not in meta.view_names:
            raise InputError(
                f"episode {ref.source_id!r} has no view {v!r}; views: {', '.join(meta.view_names)}"
            )
    counts = {v.frames for v in variants}
    if None in counts or any(c >= meta.num_frames for c in counts if c):
        positions = list(range(meta.num_frames))
    else:
        positions = sorted({p for c in counts for p in even_positions(meta.num_frames, c)})
    folder = root / "episodes" / ref.source_id
    want = None if len(positions) == meta.num_frames else positions
    pixels = {v: read_video(folder / f"{v}.mp4", want) for v in sorted(views)}
    for v, arr in pixels.items():
        if len(arr) != len(positions):
            raise InputError(
                f"{folder / (v + '.mp4')}: {len(arr)} frames but episode.json lists "
                f"{meta.num_frames}"
            )
    loaded = meta if want is None else meta.select(positions)
    loaded = loaded.model_copy(update={"views": pixels})
    meta = meta.model_copy(update={"id": ref.id})
    return meta, loaded.model_copy(update={"id": ref.id})


def _load_from_source(ref: EpisodeRef, variants: list[Variant]) -> tuple[Episode, Episode]:
    from rover.io.source import open_source, with_frame_number_truth

    counts = {v.frames for v in variants}
    frames = None if None in counts else max(c for c in counts if c)
    views = [v for v in needed_views(variants) if v]
    only = views[0] if views and needed_views(variants) == views[:1] else None
    reader = open_source(ref.origin, view=only)
    episode = reader.read(ref.source_id, frames=frames)
    if views:
        # sources decode one camera per read: read each view a variant asks for and keep
        # it under the name the variant uses (a short name such as "wrist" included)
        pixels = dict(episode.views)
        for v in views:
            if v not in pixels:
                one = (
                    episode
                    if v == only
                    else open_source(ref.origin, view=v).read(ref.source_id, frames=frames)
                )
                pixels[v] = one.views[one.view]
        episode = episode.model_copy(update={"views": pixels})
    if episode.truth is None:
        episode = with_frame_number_truth(episode)
    episode = episode.model_copy(update={"id": ref.id, "source": episode.source or ref.origin})
    meta = episode.model_copy(update={"views": {}})
    return meta, episode


def variant_episode(episode: Episode, full_indices: list[int], variant: Variant) -> Episode:
    """The episode as this variant's method sees it: its frames, its view.

    `full_indices` are the frame indices of the whole stored episode; the variant keeps
    `even_positions(len(full_indices), frames)` of them. Works on metadata-only episodes too
    (for scoring), where the view is set without checking pixels.
    """
    ep = episode
    if variant.frames is not None and variant.frames < len(full_indices):
        wanted = [full_indices[p] for p in even_positions(len(full_indices), variant.frames)]
        where = {idx: pos for pos, idx in enumerate(ep.frame_indices)}
        missing = [i for i in wanted if i not in where]
        if missing:
            raise InputError(f"episode {ep.id!r}: frame {missing[0]} was not loaded")
        ep = ep.select([where[i] for i in wanted])
    if variant.view is not None:
        if ep.views:
            ep = ep.with_view(variant.view)
        else:
            if variant.view not in ep.view_names:
                raise InputError(f"episode {ep.id!r} has no view {variant.view!r}")
            ep = ep.model_copy(update={"default_view": variant.view})
    if ep.views:
        # keep only the pixels this variant looks at
        ep = ep.model_copy(update={"views": {ep.view: ep.views[ep.view]}})
    return ep
