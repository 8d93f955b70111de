"""The `twin` command line: builds the Typer app from the command modules; the error boundary."""

from __future__ import annotations

import sys

import typer

from twin_cli.cli import commands

app = typer.Typer(
    name="twin",
    help="A MuJoCo digital twin for robots described for Gazebo: convert, spawn, run, validate.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
commands.register_all(app)


@app.callback()
def _root() -> None:
    """twin: convert, spawn, run and validate robots described for Gazebo, on MuJoCo."""


@app.command()
def version() -> None:
    """Print twin's version."""
    from importlib.metadata import version as _version

    print(f"twin {_version('twin')}")


def main() -> None:
    """Console entry point: known errors become one message on stderr and exit code 2.

    `--debug` anywhere on the command line re-raises with the traceback instead.
    """
    debug = "--debug" in sys.argv
    if debug:
        sys.argv = [a for a in sys.argv if a != "--debug"]
    from converters.errors import ConversionError
    from twin_cli.cli.output import error
    from twin_cli.errors import TwinError

    try:
        app()  # standalone: typer itself turns usage errors into exit code 2
    except (ConversionError, TwinError) as exc:
        if debug:
            raise
        error(str(exc))
        sys.exit(getattr(exc, "exit_code", 2))


if __name__ == "__main__":
    main()
