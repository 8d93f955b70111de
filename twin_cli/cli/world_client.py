"""How a world command reaches its world's server, and gz's words when none runs."""

from __future__ import annotations

import sys
from typing import Any


def connect_world(
    world: str, *, start: bool = False, serve_args: tuple[str, ...] = (), announce: Any = None
) -> Any:
    """A client of the world's server; only `spawn` and `load` may start one in the background.

    Raises:
        NotRunningError: no server runs (the CLI boundary prints gz's line, exit code 1).
    """
    from twin_cli.server import connection

    return connection.connect(world, start=start, serve_args=serve_args, announce=announce)


def not_running(exc: Exception | None = None) -> SystemExit:
    """gz's readiness-probe wording on stderr (and what died, if so), exit code 1."""
    sys.stderr.write(f"{exc or 'An instance of twin is not running.'}\n")
    return SystemExit(1)
