"""The world server and its client: HTTP over a Unix socket (or loopback TCP), like gzserver.

`app` is the FastAPI API over one World, `models` its validated request bodies, `process` runs a
server process, `runtime` owns the per-user socket, pid, log and token files, and `client` (with
`connection`, which starts and stops servers) talks to a server without importing mujoco, numpy
or fastapi (so names load lazily here).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.server.app import create_app
    from twin_cli.server.client import Client
    from twin_cli.server.connection import connect, stop
    from twin_cli.server.process import ServeOptions, serve

__all__ = ["Client", "ServeOptions", "connect", "create_app", "serve", "stop"]

__getattr__ = lazy_getattr(
    "twin_cli.server",
    {
        "Client": "twin_cli.server.client",
        "connect": "twin_cli.server.connection",
        "stop": "twin_cli.server.connection",
        "create_app": "twin_cli.server.app",
        "ServeOptions": "twin_cli.server.process",
        "serve": "twin_cli.server.process",
    },
)
