"""Command modules, one per group; each has `register(app)` and imports nothing heavy at top."""

from __future__ import annotations

import importlib

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
