"""The `rover` command line: one Typer app; each command lives in `rover.commands.<name>`.

Errors a user can act on (`RoverError`) print one line and exit non-zero; anything else
is a bug and keeps its traceback (with `ROVER_DEBUG=1`, RoverErrors do too).
"""

from __future__ import annotations

import importlib
import os
import sys

import typer
from rich.console import Console

from rover import __version__
from rover.errors import RoverError

app = typer.Typer(
    name="rover",
    help="Recursive reasoning over robot videos with vision-language models (ROVER).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

# command name -> module under rover.commands exposing `register(app)`
COMMANDS = ["reason", "generate", "eval", "report", "demo"]


def _version(value: bool) -> None:
    if value:
        typer.echo(f"rover {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Show the version and exit."
    ),
) -> None:
    """Recursive reasoning over robot videos with vision-language models (ROVER)."""


for _name in COMMANDS:
    try:
        _mod = importlib.import_module(f"rover.commands.{_name}")
    except ModuleNotFoundError as _exc:  # a command still being built is simply absent
        if _exc.name != f"rover.commands.{_name}":
            raise
        continue
    _mod.register(app)


def main() -> None:
    err = Console(stderr=True, highlight=False)
    try:
        app()
    except RoverError as exc:
        if os.environ.get("ROVER_DEBUG"):
            raise
        err.print(f"[bold red]error:[/] {exc}", markup=True, soft_wrap=True)
        sys.exit(exc.exit_code)
    except KeyboardInterrupt:
        err.print("interrupted; rerun the same command (with --resume where offered) to continue")
        sys.exit(130)


if __name__ == "__main__":
    main()
