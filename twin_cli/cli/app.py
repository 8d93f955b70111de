"""The `twin` command line: world commands on the fast path, the rest through the Typer app.

`main` first offers the command line to `twin_cli.cli.fast`, which runs plain world commands
without importing Typer; everything else (help, usage errors, convert, validate, serve) goes
to the Typer app, built on first use. `from twin_cli.cli.app import app` still gives that app.
"""

from __future__ import annotations

import sys
from functools import cache
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import typer

HELP = "A MuJoCo digital twin for robots described for Gazebo: convert, spawn, run, validate."


@cache
def build_app() -> typer.Typer:
    """The Typer app with every command module registered (importing typer costs ~55 ms)."""
    import typer

    from twin_cli.cli import commands

    app = typer.Typer(
        name="twin",
        help=HELP,
        no_args_is_help=True,
        add_completion=False,
        pretty_exceptions_enable=False,
    )
    commands.register_all(app)
    app.callback()(_root)
    app.command()(version)
    return app


def _root() -> None:
    """twin: convert, spawn, run and validate robots described for Gazebo, on MuJoCo."""


def version() -> None:
    """Print twin's version."""
    from importlib.metadata import version as _version

    print(f"twin {_version('twin')}")


def __getattr__(name: str) -> Any:
    """`app`: the Typer app, built on first access (PEP 562)."""
    if name == "app":
        return build_app()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _known(exc: Exception) -> bool:
    """Whether `exc` is a TwinError or ConversionError, whose message is meant for the user.

    `converters.errors` is imported only here, on the error path (~14 ms a command saves).
    """
    from twin_cli.errors import TwinError

    if isinstance(exc, TwinError):
        return True
    from converters.errors import ConversionError

    return isinstance(exc, ConversionError)


def main() -> None:
    """Console entry point: known errors become one message on stderr and exit code 2.

    `--debug` anywhere on the command line re-raises with the traceback instead.
    """
    debug = "--debug" in sys.argv
    if debug:
        sys.argv = [a for a in sys.argv if a != "--debug"]
    from twin_cli.cli import fast

    try:
        if not fast.run(sys.argv[1:]):
            build_app()()  # standalone: typer itself turns usage errors into exit code 2
    except Exception as exc:
        if debug or not _known(exc):
            raise
        from twin_cli.cli.output import error

        error(str(exc))
        sys.exit(getattr(exc, "exit_code", 2))


if __name__ == "__main__":
    main()
