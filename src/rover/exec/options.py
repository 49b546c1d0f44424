"""The Typer option both `rover generate` and `rover eval` take to reach a Ray cluster."""

from __future__ import annotations

from typing import Annotated

import typer

RayAddressOpt = Annotated[
    str | None,
    typer.Option(
        "--ray-address",
        help="--executor ray: 'auto' or host:port of a running cluster (default: a local Ray).",
    ),
]
