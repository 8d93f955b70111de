"""The Foxglove stream's front door: Host and Origin checked before a WebSocket reaches the SDK.

foxglove-sdk's server has no hook on the handshake, so it cannot refuse a page of another site,
nor a DNS-rebound name. twin therefore runs the SDK on a loopback port that browsers refuse to
open (their "unsafe ports": IRC's 6665-6669 and the like, `twin_cli.record.foxglove.INNER_PORTS`),
and serves the port the
user asked for from this relay, in a process of its own so relaying costs the world's loop
nothing. The relay accepts a handshake only when:
  - Host names the address it is bound to (as the viewer's guard, `twin_cli.view.guard`);
  - Origin is absent (scripts, native clients) or a page allowed to show the stream:
    Foxglove's web app, a local app page (`file://`), or one listed in TWIN_FOXGLOVE_ORIGINS
    (comma-separated). `null`, what a sandboxed frame of any site sends, is not allowed unless
    listed;
  - the client speaks the SDK's subprotocol;
and then copies frames both ways between the client and the SDK.

Run as `python -m twin_cli.view.foxglove_guard HOST PORT INNER_PORT`; it prints the port it
bound on its first line and ends when its standard input closes: the server holds the other end,
so the guard ends with the server however it ends (a parent-death signal would follow the thread
that started it, not the process).
"""

from __future__ import annotations

import asyncio
import os
import sys
from http import HTTPStatus
from typing import Any

from twin_cli.view.guard import ViewGuard

ALLOWED_BY_DEFAULT = ("https://app.foxglove.dev", "file://")
ORIGINS_VARIABLE = "TWIN_FOXGLOVE_ORIGINS"
SUBPROTOCOL = "foxglove.sdk.v1"  # the one the SDK (0.30) speaks; it refuses clients without it


def origin_key(origin: str) -> str:
    """An origin as compared: lower case, trailing slashes dropped (`file://` → `file:`), the
    same for the allowed ones and the one a page sends."""
    return origin.strip().rstrip("/").lower()


def allowed_origins() -> frozenset[str]:
    """Foxglove's web app, local app pages and the origins listed in TWIN_FOXGLOVE_ORIGINS."""
    extra = os.environ.get(ORIGINS_VARIABLE, "")
    listed = [o for o in extra.split(",") if o.strip()]
    return frozenset(origin_key(o) for o in (*ALLOWED_BY_DEFAULT, *listed))


def refusal(guard: ViewGuard, request: Any, origins: frozenset[str]) -> str | None:
    """Why a handshake is refused (None: let it through)."""
    hosts = request.headers.get_all("Host")
    given = hosts[0] if len(hosts) == 1 else None
    if given is None or not guard.host_allowed(given):
        return f"Host {given!r} is not this stream's address ({guard.host}:{guard.port})"
    sent = request.headers.get_all("Origin")
    if sent and (len(sent) > 1 or origin_key(sent[0]) not in origins):
        return (
            f"Origin {sent!r} may not open this stream; allow a page with "
            f"{ORIGINS_VARIABLE}=https://its.origin (Foxglove's web app is allowed)"
        )
    offered = ",".join(request.headers.get_all("Sec-WebSocket-Protocol")).replace(" ", "")
    if SUBPROTOCOL not in offered.split(","):
        return f"this stream speaks {SUBPROTOCOL}: use a Foxglove client that offers it"
    return None


async def _relay(client: Any, inner_port: int) -> None:
    from websockets.asyncio.client import connect

    uri = f"ws://127.0.0.1:{inner_port}/"
    async with connect(uri, subprotocols=[SUBPROTOCOL], max_size=None, compression=None) as inner:
        await asyncio.gather(_pump(client, inner), _pump(inner, client), return_exceptions=True)
        await client.close()


async def _pump(source: Any, sink: Any) -> None:
    """Copies every frame from `source` to `sink` until either side closes."""
    try:
        async for frame in source:
            await sink.send(frame)
    finally:
        await sink.close()


async def serve(host: str, port: int, inner_port: int) -> None:
    """Serves the guarded port until the process ends; prints the bound port first."""
    from websockets.asyncio.server import serve as ws_serve

    origins = allowed_origins()
    guard_for: dict[str, ViewGuard] = {}

    def process_request(connection: Any, request: Any) -> Any:
        guard = guard_for["guard"]
        why = refusal(guard, request, origins)
        if why is not None:
            return connection.respond(HTTPStatus.FORBIDDEN, f"twin foxglove: {why}\n")
        return None

    def select(connection: Any, offered: Any) -> Any:
        return SUBPROTOCOL if SUBPROTOCOL in offered else None

    async with ws_serve(
        lambda client: _relay(client, inner_port),
        host,
        port,
        process_request=process_request,
        select_subprotocol=select,
        max_size=None,
        compression=None,
    ) as server:
        bound = server.sockets[0].getsockname()[1]
        guard_for["guard"] = ViewGuard(host, int(bound))
        print(bound, flush=True)
        await _stdin_closed()


async def _stdin_closed() -> None:
    """Returns when standard input reaches its end (the server closed it, or ended)."""
    loop, closed = asyncio.get_running_loop(), asyncio.Event()
    fd = sys.stdin.fileno()

    def readable() -> None:
        if not os.read(fd, 4096):
            loop.remove_reader(fd)
            closed.set()

    loop.add_reader(fd, readable)
    await closed.wait()


def main(argv: list[str]) -> None:
    host, port, inner_port = argv[0], int(argv[1]), int(argv[2])
    asyncio.run(serve(host, port, inner_port))


if __name__ == "__main__":
    main(sys.argv[1:])
