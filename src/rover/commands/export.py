"""`rover export`: a generated benchmark as a LeRobot v3.0 dataset.

    rover export bundled --format lerobot --out exports/rover_bundled

The result loads with `LeRobotDataset` and the Hub's dataset viewer; the ground truth
rides along as per-frame features and episode metadata (`rover.io.lerobot_export`), and
`lerobot:exports/rover_bundled` reads it back exactly.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from rover.console import esc, make_console
from rover.errors import InputError

FORMATS = ("lerobot",)


def register(app: typer.Typer) -> None:
    app.command("export")(export_command)


def export_command(
    dataset: Annotated[
        Path, typer.Argument(help="A rover dataset directory ('bundled': the shipped one).")
    ],
    out: Annotated[Path, typer.Option("--out", "-o", help="New folder to write.")],
    format: Annotated[str, typer.Option("--format", help="Output format: lerobot.")] = "lerobot",
    fps: Annotated[
        int | None,
        typer.Option("--fps", help="Dataset frame rate (default: the episodes' median)."),
    ] = None,
) -> None:
    """Export a rover dataset (frames and ground truth) as a LeRobot v3.0 dataset."""
    from rover.io.lerobot_export import export_lerobot

    if format.lower() not in FORMATS:
        raise InputError(f"unknown --format {format!r}; valid formats: {', '.join(FORMATS)}")
    if fps is not None and fps <= 0:
        raise InputError(f"--fps must be positive, got {fps}")
    if str(dataset) == "bundled" and not dataset.exists():
        from rover.sim import bundled_dataset_path

        dataset = bundled_dataset_path()
    if not dataset.exists():
        raise InputError(f"{dataset}: no such dataset directory")
    info = export_lerobot(dataset, out, fps=fps)
    cameras = [k for k, f in info["features"].items() if f["dtype"] == "video"]
    make_console().print(
        f"exported {info['total_episodes']} episodes ({info['total_frames']} frames, "
        f"{len(cameras)} cameras, {info['fps']} fps) as LeRobot {info['codebase_version']} "
        f"to {esc(out)}",
        soft_wrap=True,
    )
