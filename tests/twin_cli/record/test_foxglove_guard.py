"""The Foxglove stream cannot act on the world: what it advertises, and what a client's writes do.

foxglove-sdk's server has no Host or Origin check to hook (docs/viewer.md, "The Foxglove stream's
guard"), so a page that reaches the loopback port can connect. What keeps the world safe is that
the server offers reading only: its serverInfo advertises the Time capability and nothing that
writes (client publish, parameters, services, playback control), and a client's attempts to
write anyway are refused by the server, not executed.
"""

from __future__ import annotations

import asyncio
import json

from twin_cli.record.foxglove import LiveStream

SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]
WRITING = {"clientPublish", "parameters", "parametersSubscribe", "services", "assets",
           "connectionGraph", "playbackControl"}  # fmt: skip


def test_the_stream_offers_reading_only_even_to_a_foreign_origin() -> None:
    import websockets

    stream = LiveStream(port=0)

    async def session() -> tuple[dict, list[dict]]:
        url = f"ws://127.0.0.1:{stream.port}"
        headers = {"Origin": "http://attacker.example"}
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

    try:
        info, replies = asyncio.run(session())
    finally:
        stream.close()
    assert info["op"] == "serverInfo", info
    offered = set(info.get("capabilities", []))
    assert offered == {"time"}, f"advertised capabilities: {sorted(offered)}"
    assert not offered & WRITING
    statuses = [r for r in replies if r.get("op") == "status"]
    assert [r["level"] for r in statuses] == [2, 2, 2], replies  # one error (2) per write
    assert "does not support clientPublish" in statuses[0]["message"], statuses
