"""The `twin` command line: world commands on the fast path, the rest through the Typer app.

`main` first offers the command line to `twin_cli.cli.fast`, which runs plain world commands
without importing Typer; everything else (help, usage errors, convert, validate, serve) goes
to the Typer app, built on first use. Errors of either path, usage errors included, end in
`main`'s one boundary. `from twin_cli.cli.app import app` still gives that app.
"""

from __future__ import annotations

import sys
from functools import cache
from typing import TYPE_CHECKING, Any, NoReturn

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
    app.callback()(commands.root)
    app.command("version")(version)
    return app


def version() -> None:
    """Print twin's version (the installed distribution's, as `twin --version` does)."""
    from twin_cli.cli.output import print_version

    print_version()


def __getattr__(name: str) -> Any:
    """`app`: the Typer app, built on first access (PEP 562)."""
    if name == "app":
        return build_app()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _known(exc: Exception) -> bool:
    """Whether `exc` is a TwinError, OutputFileError or ConversionError, meant for the user.

    `converters.errors` is imported only here, on the error path (~14 ms a command saves).
    """
    from twin_cli.errors import TwinError
    from twin_cli.files.output_files import OutputFileError

    if isinstance(exc, TwinError | OutputFileError):
        return True
    from converters.errors import ConversionError

    return isinstance(exc, ConversionError)


# Exit code of an unexpected failure (sysexits' EX_SOFTWARE): a bug, never bad input.
INTERNAL_ERROR = 70
PROG = "twin"  # the program name usage lines show, however the entry point was started


def main() -> None:
    """Console entry point and the CLI's one error boundary.

    Usage errors (a BadOption an action raises, on either path, or click's own) print the
    command's usage and one message, exit code 2; other known errors one message and their exit
    code; anything else is a bug: one line saying where its traceback was written, exit code 70.
    `--debug` anywhere on the command line re-raises the others with their traceback instead.
    """
    debug = "--debug" in sys.argv
    if debug:
        sys.argv = [a for a in sys.argv if a != "--debug"]
    if sys.argv[1:] == ["--version"]:
        return version()
    from twin_cli.cli import fast

    try:
        if not fast.run(sys.argv[1:]):
            _run_app(sys.argv[1:])
        sys.stdout.flush()  # a reader that went away (`| head -1`) shows up here, if not before
    except BrokenPipeError:
        _reader_gone()
    except Exception as exc:
        _fail(exc, debug)


def _reader_gone() -> NoReturn:
    """The command's reader closed the pipe (`twin list | head -1`): what it wanted it has.

    Standard output goes to /dev/null so that the interpreter's last flush cannot fail again.
    """
    import os

    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    sys.exit(0)


def narrowed(app: typer.Typer, argv: list[str]) -> typer.Typer:
    """A copy of `app` with only the command or group `argv` names, when it names one.

    Typer builds a click command, with every parameter read from its signature, for each command
    the app has (~60 ms for twin's, a tenth of `twin convert`), while a run needs only the one
    it runs; usage lines and errors are the same. `twin --help` and an unknown name get the
    whole app, so the list of commands and click's "No such command" stay as they were.
    """
    if not argv or argv[0].startswith("-"):
        return app
    name = argv[0]
    commands = [c for c in app.registered_commands if c.name == name]
    groups = [g for g in app.registered_groups if g.name == name]
    if not (commands or groups):
        return app
    import copy

    alone = copy.copy(app)  # `build_app`'s app is shared: it keeps every command
    alone.registered_commands, alone.registered_groups = commands, groups
    return alone


def _run_app(argv: list[str]) -> None:
    """Runs the Typer app, its click errors left to `main`'s boundary (not standalone mode)."""
    try:
        code = narrowed(build_app(), argv)(args=argv, prog_name=PROG, standalone_mode=False)
    except SystemExit as exit_:
        # rich (help pages) and click meet a closed pipe (`twin spawn --help | head -1`) by
        # exiting 1; for twin a reader that went away is not a failure
        pacified = type(sys.stdout).__name__.lstrip("_") == "PacifyFlushWrapper"
        if pacified or isinstance(exit_.__context__, BrokenPipeError):
            _reader_gone()
        raise
    if isinstance(code, int) and code:  # click's Exit (an exit code, e.g. 130 after Ctrl-C)
        sys.exit(code)


def _fail(exc: Exception, debug: bool) -> NoReturn:
    """Print `exc` as the user needs it and exit with its code (`debug`: re-raise all but usage)."""
    from twin_cli.cli.output import error
    from twin_cli.cli.pairs import BadOption
    from twin_cli.errors import NotRunningError

    if isinstance(exc, BadOption) or _from_click(exc):
        _click_error(exc)
    if debug:
        raise exc
    if isinstance(exc, NotRunningError):  # gz's readiness-probe line as it starts, exit code 2
        sys.stderr.write(f"{exc}\n")
        sys.exit(exc.exit_code)
    if _known(exc):
        error(str(exc))
        sys.exit(getattr(exc, "exit_code", 2))
    error(_internal_error(exc))
    sys.exit(INTERNAL_ERROR)


def _from_click(exc: Exception) -> bool:
    """Whether `exc` is click's (a usage error, Abort); click is imported only if Typer ran."""
    click = sys.modules.get("click")
    return click is not None and isinstance(exc, click.ClickException | click.Abort)


def _click_error(exc: Exception) -> NoReturn:
    """A usage error as Typer prints one (the command's usage, the message), or click's Abort.

    A BadOption becomes a usage error of the command it came from (exit code 2).
    """
    import click

    if isinstance(exc, click.Abort):
        sys.stderr.write("Aborted!\n")
        sys.exit(1)
    if not isinstance(exc, click.ClickException):
        exc = click.UsageError(str(exc), _command_context(sys.argv[1:]))
    try:
        from typer import rich_utils
    except ImportError:  # Typer without rich prints click's plain form
        exc.show()
    else:
        rich_utils.rich_format_error(exc)
    sys.exit(exc.exit_code)


def _command_context(argv: list[str]) -> Any:
    """A click context of the command `argv` names, for its usage line (the app's if none)."""
    import click
    import typer

    group = typer.main.get_command(build_app())
    root = click.Context(group, info_name=PROG)
    command = group.get_command(root, argv[0]) if argv else None
    return root if command is None else click.Context(command, info_name=argv[0], parent=root)


def _internal_error(exc: Exception) -> str:
    """Write the traceback to a private file; the one line that says what failed and where."""
    import os
    import tempfile
    import traceback

    fd, path = tempfile.mkstemp(prefix="twin-error-", suffix=".txt")
    with os.fdopen(fd, "w") as handle:
        handle.write(f"twin {' '.join(sys.argv[1:])}\n\n")
        traceback.print_exception(exc, file=handle)
    return (
        f"internal error: {type(exc).__name__}: {exc}; the traceback is in {path} "
        "(run again with --debug to see it); please report it with that file"
    )


if __name__ == "__main__":
    main()
