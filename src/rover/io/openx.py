"""The OpenX-Embodiment VOC benchmark of App. L: its 50 datasets and episode sampling.

The paper (after GVL) evaluates on 20 randomly chosen episodes from each of 50 OpenX
datasets, with normalised frame number as ground truth and VOC (Spearman correlation with
frame order) as the metric. This module knows the dataset names and the paper's
reported numbers, finds the datasets a user has downloaded, and draws the episodes
reproducibly; `rover eval` runs the methods and computes VOC.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from rover.errors import InputError
from rover.io.source import open_source, sample_episode_ids

# dataset -> ((GVL, ROVER) with Gemini-1.5-Pro, (GVL, ROVER) with GPT-4o); None: not
# reported in that table. Correlation with frame number, App. L tables.
PAPER_VOC: dict[str, tuple[tuple[float, float] | None, tuple[float, float] | None]] = {
    "utokyo_xarm_pick_and_place_converted_externally_to_rlds": ((0.753, 0.898), (0.726, 0.822)),
    "utokyo_xarm_bimanual_converted_externally_to_rlds": ((0.822, 0.89), (0.714, 0.874)),
    "nyu_door_opening_surprising_effectiveness": ((0.668, 0.879), (0.891, 0.928)),
    "berkeley_autolab_ur5": ((0.761, 0.874), (0.749, 0.894)),
    "utokyo_pr2_tabletop_manipulation_converted_externally_to_rlds": (
        (0.619, 0.87),
        (0.722, 0.867),
    ),
    "maniskill_dataset_converted_externally_to_rlds": ((0.74, 0.866), (0.527, 0.787)),
    "utokyo_pr2_opening_fridge_converted_externally_to_rlds": ((0.824, 0.856), (0.907, 0.969)),
    "fractal20220817_data": ((0.762, 0.817), (0.788, 0.879)),
    "iamlab_cmu_pickup_insert_converted_externally_to_rlds": ((0.513, 0.805), (0.554, 0.824)),
    "toto": ((0.564, 0.78), (0.717, 0.851)),
    "ucsd_kitchen_dataset_converted_externally_to_rlds": ((0.529, 0.768), (0.629, 0.814)),
    "utaustin_mutex": ((0.576, 0.767), (0.837, 0.893)),
    "asu_table_top_converted_externally_to_rlds": ((0.477, 0.762), (0.505, 0.803)),
    "austin_sirius_dataset_converted_externally_to_rlds": ((0.539, 0.755), (0.717, 0.867)),
    "dobbe": ((0.487, 0.754), (0.568, 0.829)),
    "berkeley_cable_routing": ((0.488, 0.752), (0.278, 0.676)),
    "berkeley_rpt_converted_externally_to_rlds": ((0.495, 0.748), (0.616, 0.781)),
    "viola": ((0.415, 0.747), (0.503, 0.804)),
    "fmb": ((0.555, 0.739), None),
    "austin_buds_dataset_converted_externally_to_rlds": ((0.35, 0.727), (0.458, 0.728)),
    "usc_cloth_sim_converted_externally_to_rlds": ((0.457, 0.722), (0.466, 0.765)),
    "bridge": ((0.457, 0.717), (0.661, 0.799)),
    "jaco_play": ((0.414, 0.71), (0.57, 0.786)),
    "stanford_hydra_dataset_converted_externally_to_rlds": ((0.351, 0.701), (0.178, 0.598)),
    "bc_z": ((0.397, 0.696), (0.158, 0.591)),
    "berkeley_mvp_converted_externally_to_rlds": ((0.36, 0.68), (0.835, 0.889)),
    "cmu_stretch": ((0.276, 0.677), (0.14, 0.598)),
    "tokyo_u_lsmo_converted_externally_to_rlds": ((0.362, 0.639), (0.394, 0.674)),
    "berkeley_fanuc_manipulation": ((0.252, 0.632), (0.603, 0.807)),
    "roboturk": ((0.314, 0.631), (0.586, 0.769)),
    "ucsd_pick_and_place_dataset_converted_externally_to_rlds": ((0.281, 0.615), (0.245, 0.663)),
    "dlr_edan_shared_control_converted_externally_to_rlds": ((0.119, 0.598), (0.696, 0.84)),
    "dlr_sara_pour_converted_externally_to_rlds": ((0.115, 0.564), (0.244, 0.615)),
    "droid": ((-0.002, 0.546), None),
    "taco_play": ((0.083, 0.539), (-0.094, 0.299)),
    "stanford_robocook_converted_externally_to_rlds": ((-0.01, 0.513), (0.206, 0.598)),
    "imperialcollege_sawyer_wrist_cam": ((-0.038, 0.432), (0.219, 0.602)),
    "kaist_nonprehensile_converted_externally_to_rlds": ((-0.021, 0.425), (0.483, 0.704)),
    "austin_sailor_dataset_converted_externally_to_rlds": ((-0.072, 0.371), (0.353, 0.681)),
    "kuka": ((0.304, 0.316), (0.15, 0.17)),
    "cmu_play_fusion": ((-0.096, 0.304), (0.374, 0.661)),
    "stanford_kuka_multimodal_dataset_converted_externally_to_rlds": (
        (-0.11, 0.295),
        (-0.042, 0.434),
    ),
    "nyu_franka_play_dataset_converted_externally_to_rlds": ((-0.139, 0.287), (0.182, 0.567)),
    "stanford_mask_vit_converted_externally_to_rlds": ((-0.131, 0.27), (-0.042, 0.433)),
    "uiuc_d3field": ((-0.212, 0.169), (0.524, 0.73)),
    "robo_net": ((-0.24, 0.096), (0.367, 0.438)),
    "columbia_cairlab_pusht_real": ((-0.229, 0.095), (-0.048, 0.416)),
    "dlr_sara_grid_clamp_converted_externally_to_rlds": ((-0.301, -0.024), (-0.301, -0.047)),
    "cmu_franka_exploration_dataset_converted_externally_to_rlds": (
        (-0.23, -0.078),
        (-0.064, 0.356),
    ),
    "eth_agent_affordances": (None, (-0.088, 0.416)),
}
OPENX_DATASETS: tuple[str, ...] = tuple(PAPER_VOC)
EPISODES_PER_DATASET = 20


@dataclass(frozen=True)
class BenchmarkEpisode:
    """One episode of the benchmark: which dataset, which source spec, which id."""

    dataset: str
    spec: str
    episode_id: str


def discover_openx(root: Path, names: list[str] | None = None) -> dict[str, str]:
    """Source specs of the OpenX datasets found under `root`, by dataset name.

    Looks for `root/<name>/` holding either an RLDS build (`features.json` or TFRecord
    shards, possibly inside one version folder such as `0.1.0/`) or a LeRobot conversion
    (`meta/info.json`). `names` defaults to the 50 datasets of App. L; datasets that are
    not there are simply left out, so a partial download still runs.
    """
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: no such directory (expected one folder per OpenX dataset)")
    found: dict[str, str] = {}
    for name in names or list(OPENX_DATASETS):
        folder = root / name
        if not folder.is_dir():
            continue
        if (folder / "meta" / "info.json").exists():
            found[name] = f"lerobot:{folder}"
        elif _has_rlds(folder) or any(_has_rlds(p) for p in folder.iterdir() if p.is_dir()):
            found[name] = f"rlds:{folder}"
    return found


def benchmark_episodes(
    specs: dict[str, str], per_dataset: int = EPISODES_PER_DATASET, seed: int = 0
) -> list[BenchmarkEpisode]:
    """`per_dataset` episodes from each dataset, the same ones for the same seed."""
    out: list[BenchmarkEpisode] = []
    for name, spec in specs.items():
        reader = open_source(spec)
        for episode_id in sample_episode_ids(reader, per_dataset, seed):
            out.append(BenchmarkEpisode(name, spec, episode_id))
    return out


def _has_rlds(folder: Path) -> bool:
    return (folder / "features.json").exists() or any(folder.glob("*.tfrecord*"))
