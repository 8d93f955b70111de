"""World commands (Gazebo's verbs) for Typer, built from `twin_cli.cli.world_table`.

Each command is declared once, in that table: its help, arguments and options, and the
`world_actions` function it calls. The fast path (`twin_cli.cli.fast`) reads the same table
without importing Typer; here each entry becomes a function whose signature Typer reads, so
`--help` and click's usage errors come from Typer. A value an action refuses (BadOption) is a
usage error too, printed by the error boundary in `app.main`.
This module and everything it imports stay client-side: no mujoco, numpy or fastapi (an import
contract in `make lint` holds it to that); `twin serve` lives in `serve.py`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import typer

from twin_cli.cli import options
from twin_cli.cli.world_table import COMMANDS as TABLE
from twin_cli.cli.world_table import Command


def command(spec: Command) -> Callable[..., None]:
    """A function Typer registers as `spec`: the table's help and parameters, then its action.

    The actions' module is imported when a command runs: registering every command for
    another one (`twin convert`) does not pay for it (44 ms, `-X importtime`)."""

    def run(**kwargs: Any) -> None:
        from twin_cli.cli import world_actions

        getattr(world_actions, spec.action)(**kwargs)

    run.__name__ = run.__qualname__ = spec.action
    run.__doc__ = spec.help
    params = [options.parameter(param) for param in spec.params]
    run.__signature__ = inspect.Signature(params, return_annotation=None)
    return run


COMMANDS: dict[str, Callable[..., None]] = {name: command(spec) for name, spec in TABLE.items()}


def register(app: typer.Typer) -> None:
    """Add the world commands to the `twin` app."""
    for name, function in COMMANDS.items():
        app.command(name)(function)
