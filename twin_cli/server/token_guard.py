"""The bearer-token guard of a world server's TCP listener."""

from __future__ import annotations

import secrets
from typing import Any

from twin_cli.server.error_replies import error_reply


class TokenGuard:
    """ASGI middleware: requests that arrive over TCP must carry `Authorization: Bearer TOKEN`.

    Unix-socket requests pass (the 0700 directory and 0600 socket already restrict them to
    the user). uvicorn reports a Unix socket's scope["server"] as (path, None).
    """

    def __init__(self, app: Any, token: str | None) -> None:
        self.app = app
        self.expected = f"Bearer {token}".encode() if token else None

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        server = scope.get("server") or (None, None)
        if scope["type"] == "http" and server[1] is not None:
            given = dict(scope.get("headers") or []).get(b"authorization", b"")
            if self.expected is None or not secrets.compare_digest(given, self.expected):
                reply = error_reply(
                    401,
                    "RequestError",
                    "missing or wrong bearer token; send "
                    "`Authorization: Bearer <contents of the world's .token file>`",
                )
                await reply(scope, receive, send)
                return
        await self.app(scope, receive, send)
