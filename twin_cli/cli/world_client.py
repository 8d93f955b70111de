"""How a world command reaches its world's server, and gz's words when none runs."""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from twin_cli.errors import NotRunningError


def connect_world(
    world: str, *, start: bool = False, serve_args: tuple[str, ...] = (), announce: Any = None
) -> Any:
    """A client of the world's server; only `spawn` and `load` may start one in the background.

    Raises:
        NotRunningError: no server runs (the CLI boundary prints gz's line and the fix, exit 2).
    """
    from twin_cli.server import connection

    return connection.connect(world, start=start, serve_args=serve_args, announce=announce)


def not_running(exc: NotRunningError) -> SystemExit:
    """gz's readiness-probe line with the fix on stderr (and what died, if so), exit code 2."""
    sys.stderr.write(f"{exc}\n")
    return SystemExit(exc.exit_code)
