"""Command modules, one per group; each has `register(app)` and imports nothing heavy at top.

`register_all` also gives every command its help with each paragraph on one line: Typer keeps
a docstring's line breaks after its first paragraph (and in the command lists, in the first),
so a docstring wrapped at the source's width printed broken mid-sentence on an 80-column
terminal. Paragraphs are separated by a blank line, as in the docstrings.
"""

from __future__ import annotations

import importlib
import inspect
from typing import Annotated

import typer

# Each module registers its commands on the app. Keep this list in the order of `twin --help`.
MODULES = (
    "convert",
    "cache",
    "serve",
    "world",
    "record",
    "sensors",
    "topics",
    "ros",
    "model",
    "validate",
    "control",
    "drive",
    "view",
)


def register_all(app: typer.Typer) -> None:
    """Register every command module; a module that fails to import is a bug, raised as such."""
    for name in MODULES:
        importlib.import_module(f"twin_cli.cli.commands.{name}").register(app)
    unwrap_app(app)


def unwrap(text: str) -> str:
    """`text` (a docstring or help string) with each paragraph joined into one line."""
    paragraphs = inspect.cleandoc(text).split("\n\n")
    return "\n\n".join(" ".join(p.split()) for p in paragraphs)


def unwrap_app(app: typer.Typer) -> None:
    """Sets every command's and group's help of `app` (and its groups') to `unwrap`'s form."""
    for info in app.registered_commands:
        text = info.help or inspect.getdoc(info.callback)
        info.help = unwrap(text) if text else text
    for group in app.registered_groups:
        sub = group.typer_instance
        if sub is None:
            continue
        callback = sub.registered_callback
        text = group.help or sub.info.help or (callback and inspect.getdoc(callback.callback))
        group.help = unwrap(text) if isinstance(text, str) else text
        unwrap_app(sub)


def _print_version(given: bool) -> None:
    """`--version` where Typer reads the line (`twin --version --help`): the version, exit 0."""
    if given:
        from twin_cli.cli.output import print_version

        print_version()
        raise typer.Exit()


def root(
    show_version: Annotated[
        bool,
        typer.Option(
            "--version",
            help="Print twin's version and exit.",
            is_eager=True,
            callback=_print_version,
        ),
    ] = False,
) -> None:
    """twin: convert, spawn, run and validate robots described for Gazebo, on MuJoCo."""
