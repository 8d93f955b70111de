"""The Foxglove stream is guarded like a local daemon and cannot act on the world.

foxglove-sdk's server has no Host or Origin check to hook, so it listens on a loopback port that
browsers refuse to open and the user's port is a guard process (`twin_cli.view.foxglove_guard`):
a foreign Origin or Host is refused before the handshake, Foxglove's web app and clients without
an Origin get through. Behind it the server offers reading only: its serverInfo advertises the
Time capability and nothing that writes, and a client's attempts to write anyway are refused.
"""

from __future__ import annotations

import asyncio
import json
import socket

import pytest

from twin_cli.record.foxglove import INNER_PORTS, LiveStream

SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]
WRITING = {"clientPublish", "parameters", "parametersSubscribe", "services", "assets",
           "connectionGraph", "playbackControl"}  # fmt: skip


@pytest.fixture
def stream():
    live = LiveStream(port=0)
    yield live
    live.close()


def _handshake(port: int, headers: dict[str, str]) -> str:
    """'open' with serverInfo received, or the refusal's HTTP status."""
    import websockets

    async def attempt() -> str:
        try:
            async with websockets.connect(
                f"ws://127.0.0.1:{port}", subprotocols=SUBPROTOCOLS, additional_headers=headers
            ) as ws:
                info = json.loads(await asyncio.wait_for(ws.recv(), 10))
                return "open" if info["op"] == "serverInfo" else str(info)
        except websockets.InvalidStatus as exc:
            return str(exc.response.status_code)

    return asyncio.run(attempt())


@pytest.mark.parametrize(
    ("headers", "expected"),
    [
        ({}, "open"),
        ({"Origin": "https://app.foxglove.dev"}, "open"),
        ({"Origin": "file://"}, "open"),
        ({"Origin": "http://attacker.example"}, "403"),
        ({"Origin": "null"}, "403"),
        ({"Host": "rebound.attacker.example"}, "403"),
    ],
    ids=["no origin", "foxglove app", "local app page", "foreign origin", "opaque", "rebound host"],
)
def test_only_this_machines_clients_and_foxglove_open_the_stream(stream, headers, expected):
    with socket.create_connection(("127.0.0.1", stream.port)):
        pass  # the guard listens
    assert _handshake(stream.port, headers) == expected, headers


def test_the_sdk_listens_where_no_browser_page_can_connect(stream) -> None:
    """The SDK's own port is one of the ports browsers refuse, on loopback only."""
    assert stream.inner_port in INNER_PORTS
    assert stream.port not in INNER_PORTS
    assert _handshake(stream.inner_port, {}) == "open", "the SDK answers there, behind the guard"


def test_a_client_without_the_sdks_subprotocol_is_told_why() -> None:
    live = LiveStream(port=0)
    try:
        import websockets

        async def attempt() -> str:
            try:
                async with websockets.connect(
                    f"ws://127.0.0.1:{live.port}", subprotocols=["foxglove.websocket.v1"]
                ):
                    return "open"
            except websockets.InvalidStatus as exc:
                return f"{exc.response.status_code} {exc.response.body.decode()}"

        assert asyncio.run(attempt()).startswith("403 twin foxglove: this stream speaks")
    finally:
        live.close()


def test_the_guard_outlives_the_thread_that_started_it_and_ends_with_close() -> None:
    """A request thread that opened the stream may end; the guard stays until close()."""
    import threading
    import time

    made: list[LiveStream] = []
    starter = threading.Thread(target=lambda: made.append(LiveStream(port=0)))
    starter.start()
    starter.join()
    live = made[0]
    time.sleep(1.0)
    assert _handshake(live.port, {}) == "open", "the guard still answers"
    live.close()
    try:
        socket.create_connection(("127.0.0.1", live.port), timeout=1).close()
        closed = False
    except OSError:
        closed = True
    assert closed, "close() ends the guard: its port no longer answers"


def test_the_stream_offers_reading_only(stream) -> None:
    import websockets

    async def session() -> tuple[dict, list[dict]]:
        url = f"ws://127.0.0.1:{stream.port}"
        headers = {"Origin": "https://app.foxglove.dev"}
        async with websockets.connect(
            url, subprotocols=SUBPROTOCOLS, additional_headers=headers
        ) as ws:
            info = json.loads(await asyncio.wait_for(ws.recv(), 10))
            for op in (
                {"op": "advertise", "channels": [{"id": 1, "topic": "/cmd_vel",
                 "encoding": "cdr", "schemaName": "geometry_msgs/msg/Twist"}]},
                {"op": "setParameters", "parameters": [{"name": "paused", "value": True}]},
                {"op": "callService", "serviceId": 1, "callId": 1, "encoding": "json"},
            ):  # fmt: skip
                await ws.send(json.dumps(op))
            replies = []
            while True:
                try:
                    frame = await asyncio.wait_for(ws.recv(), 2)
                except TimeoutError:
                    return info, replies
                if isinstance(frame, str):
                    replies.append(json.loads(frame))

    info, replies = asyncio.run(session())
    assert info["op"] == "serverInfo", info
    offered = set(info.get("capabilities", []))
    assert offered == {"time"}, f"advertised capabilities: {sorted(offered)}"
    assert not offered & WRITING
    statuses = [r for r in replies if r.get("op") == "status"]
    assert [r["level"] for r in statuses] == [2, 2, 2], replies  # one error (2) per write
    assert "does not support clientPublish" in statuses[0]["message"], statuses
