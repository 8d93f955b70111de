"""Request bodies over a stated size are refused at once (413), before any of them is parsed.

A 50 MB body used to take 19 s to be read, decoded and validated before its 422; the limit is
far above any real request (a URDF or SDF sent as text, a trajectory) and answers at once.
"""

from __future__ import annotations

from typing import Any

from starlette.exceptions import HTTPException

from twin_cli.server.error_replies import error_reply

MAX_BODY_BYTES = 16 * 1024 * 1024  # [bytes] the largest request body the server reads


class BodyLimit:
    """ASGI middleware: a declared Content-Length over `limit` gets 413 without being read, and
    a body streamed without one is cut off with 413 once it passes `limit`."""

    def __init__(self, app: Any, limit: int = MAX_BODY_BYTES) -> None:
        self.app = app
        self.limit = limit

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope.get("headers") or []).get(b"content-length")
        if declared is not None and declared.isdigit() and int(declared) > self.limit:
            await self._refuse(scope, receive, send, int(declared))
            return
        await self.app(scope, self._counted(receive), send)

    def _counted(self, receive: Any) -> Any:
        seen = 0

        async def counted() -> dict:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.limit:
                raise BodyTooLarge(seen, self.limit)
            return message

        return counted

    async def _refuse(self, scope: dict, receive: Any, send: Any, size: int) -> None:
        message = (
            f"{scope.get('method')} {scope.get('path')}: {BodyTooLarge(size, self.limit).message}"
        )
        reply = error_reply(413, "RequestError", message)
        await reply(scope, receive, send)


class BodyTooLarge(HTTPException):
    """A streamed body passed the limit: answered 413 like the app's other HTTP refusals."""

    def __init__(self, size: int, limit: int) -> None:
        self.message = (
            f"{size} bytes is over the server's limit of {limit} bytes; send a smaller "
            "description (meshes go by file path, not inline)"
        )
        super().__init__(status_code=413, detail=self.message)
