"""Command modules, one per group; each has `register(app)` and imports nothing heavy at top."""

from __future__ import annotations

import importlib
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


def _print_version(given: bool) -> None:
    """`--version` where Typer reads the line (`twin --version --help`): the version, exit 0."""
    if given:
        from twin_cli.cli.app import version

        version()
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
