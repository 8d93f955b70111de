"""World commands (Gazebo's verbs) for Typer, built from the registry (`twin_cli.cli.registry`).

Each command is declared once, on its function in `twin_cli.cli.world_commands`: its help,
arguments and options. The fast path (`twin_cli.cli.fast`) reads the same declarations without
importing Typer; here each becomes a function whose signature Typer reads, so `--help` and
click's usage errors come from Typer. A value a command refuses (BadOption) is a usage error
too, printed by the error boundary in `app.main`.
This module and everything it imports stay client-side: no mujoco, numpy or fastapi (an import
contract in `make lint` holds it to that); `twin serve` lives in `serve.py`.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import typer

from twin_cli.cli import options
from twin_cli.cli.registry import Command, world_commands


def typer_command(spec: Command) -> Callable[..., None]:
    """A function Typer registers as `spec`: its help and parameters, calling `spec.action`."""
    action = spec.action

    def run(**kwargs: Any) -> None:
        action(**kwargs)

    run.__name__ = run.__qualname__ = action.__name__
    run.__doc__ = spec.help
    params = [options.parameter(param) for param in spec.params]
    run.__signature__ = inspect.Signature(params, return_annotation=None)
    return run


def register(app: typer.Typer) -> None:
    """Add the world commands to the `twin` app."""
    for name, spec in world_commands().items():
        app.command(name)(typer_command(spec))
