"""The `rover` command line: one Typer app; each command lives in `rover.commands.<name>`.

Errors a user can act on (`RoverError`) print one line and exit non-zero; anything else
is a bug and keeps its traceback (with `ROVER_DEBUG=1`, RoverErrors do too).
"""

from __future__ import annotations

import importlib
import os
import sys

import typer

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
COMMANDS = [
    "reason",
    "generate",
    "eval",
    "report",
    "demo",
    "validate",
    "annotate",
    "export",
    "tasks",
    "watch",
]


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


def _click_exceptions():
    """Typer >= 0.25 vendors click as `typer._click`; older ones use click itself."""
    try:
        from typer._click import exceptions
    except ImportError:  # pragma: no cover - depends on the installed typer
        from click import exceptions
    return exceptions


def main() -> None:
    """Run the app; every failure a user can cause ends in one `error:` line, no traceback."""
    from rover.console import make_console, print_error

    click = _click_exceptions()

    err = make_console(stderr=True)
    debug = bool(os.environ.get("ROVER_DEBUG"))
    try:
        rc = app(standalone_mode=False)
    except click.NoArgsIsHelpError as exc:
        exc.show()
        sys.exit(exc.exit_code)
    except click.UsageError as exc:
        hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
        print_error(exc.format_message() + hint, err)
        sys.exit(exc.exit_code)
    except click.ClickException as exc:
        print_error(exc.format_message(), err)
        sys.exit(exc.exit_code)
    except RoverError as exc:
        if debug:
            raise
        print_error(exc, err)
        sys.exit(exc.exit_code)
    except OSError as exc:  # the filesystem or network said no: a fact about the machine
        if debug:
            raise
        where = f": {exc.filename}" if exc.filename else ""
        print_error(f"{exc.strerror or type(exc).__name__}{where}", err)
        sys.exit(2)
    except UnicodeDecodeError as exc:  # a file that should be text is not; say so in a line
        if debug:
            raise
        print_error(f"a file rover read is not UTF-8 text ({exc.reason} at byte {exc.start})", err)
        sys.exit(2)
    except (KeyboardInterrupt, typer.Abort):
        err.print("interrupted; rerun the same command (with --resume where offered) to continue")
        sys.exit(130)
    sys.exit(rc if isinstance(rc, int) else 0)


if __name__ == "__main__":
    main()
