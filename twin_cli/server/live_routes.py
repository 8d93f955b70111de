"""Routes of the live look inside: `/topics` (`twin topics`), `/topics/echo` (`twin topics
echo`), `/entities/{name}/model` (`twin model`) and `/conversions` (`twin spawn`'s progress).

The echo is one streamed HTTP reply (NDJSON: one message per line), not a sample route polled
by the client: polling would read the world at the client's wall-clock pace (messages missed or
repeated, each costing a request and a lock), while the stream carries every message at the
topic's rate in sim time. It stays cheap for the server: the messages are made by the echo's
own thread from copies the stepping thread takes at that rate (`twin_cli.live.echo`), and the
reply is an async generator on the event loop, so a waiting echo holds no worker thread and the
other routes keep answering. A blank line goes out after HEARTBEAT_S without a message, so a
client that went away is noticed, and its echo stopped, even while the world is paused.
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import AsyncIterator
from typing import Annotated, Any

from fastapi import APIRouter, Query, Request
from fastapi.responses import StreamingResponse
from starlette.concurrency import run_in_threadpool

from twin_cli.server.holder import WorldDep

router = APIRouter()
HEARTBEAT_S = 1.0  # [s] wall: a blank line after this long without a message
QUEUE_LINES = 1000  # lines waiting for a slow reader; past that new ones are dropped


@router.get("/topics")
def topics(world: WorldDep) -> list[dict]:
    """Every topic the world offers: name, type, rate [Hz of sim time], latched, entity, sensor,
    and the command topics `twin serve --ros` reads (`command`)."""
    from twin_cli.live import live_topics
    from twin_cli.ros.commands import with_commands

    return [t.to_dict() for t in with_commands(live_topics(world), world)]


@router.get("/conversions")
def conversions() -> list[dict]:
    """The descriptions being converted now (`twin spawn`'s progress): the file or text label,
    the stage the conversion is in, and how long it has run [s, wall]."""
    import time

    from converters.isolated import bounded

    now = time.monotonic()
    return [
        {"source": r.subject, "stage": r.stage, "seconds": round(now - r.started, 3)}
        for r in bounded.running()
    ]


@router.get("/entities/{name}/model")
def model(name: str, world: WorldDep) -> dict:
    """The entity's links, frames (world poses), joints and modes, drives, sensors, topics."""
    from twin_cli.live import describe

    return describe(world, name)


ECHO_REPLY = {
    200: {
        "description": "one JSON object per line: topic, type, time [s], message",
        "content": {"application/x-ndjson": {"schema": {"type": "string"}}},
    }
}


@router.get("/topics/echo", response_class=StreamingResponse, responses=ECHO_REPLY)
async def echo(
    request: Request,
    world: WorldDep,
    name: Annotated[str, Query(description="topic name, e.g. /robot/joint_states")],
    count: Annotated[int, Query(ge=0, description="end after this many messages (0: never)")] = 0,
    rate: Annotated[float | None, Query(description="[Hz] of sim time, state topics")] = None,
    truncate: Annotated[int, Query(ge=0, description="array/string items shown (0: all)")] = 128,
) -> StreamingResponse:
    """The topic's messages as they come, one JSON object per line: `{"topic", "type", "time",
    "message"}` (sim time [s]); an unknown topic is a 404 naming the topics there are, and a
    topic that cannot be read ends the stream with `{"error", "message"}`."""
    from twin_cli.live import Echo, find_topic

    loop = asyncio.get_running_loop()
    lines: asyncio.Queue[str] = asyncio.Queue(QUEUE_LINES)

    def deliver(item: dict) -> None:  # the echo's thread: encoding happens there
        text = json.dumps(item, separators=(",", ":")) + "\n"
        loop.call_soon_threadsafe(_offer, lines, text)

    def open_echo() -> Any:
        return Echo(world, find_topic(world, name), deliver, rate=rate, truncate=truncate).start()

    echo_ = await run_in_threadpool(open_echo)  # errors here are the usual JSON error replies
    state = request.app.state
    exiting = getattr(state, "exiting", lambda: False)
    return StreamingResponse(
        _stream(echo_, lines, count, lambda: state.holder.world is not world or exiting()),
        media_type="application/x-ndjson",
    )


def _offer(lines: asyncio.Queue[str], text: str) -> None:
    if not lines.full():
        lines.put_nowait(text)


async def _stream(
    echo: Any, lines: asyncio.Queue[str], count: int, ended: Any
) -> AsyncIterator[str]:
    """The echo's lines until `count` are sent, `ended()` (the world was replaced by `/load`,
    or the server is exiting) or the client goes away (Starlette cancels this generator); the
    echo is stopped in every case."""
    sent = 0
    try:
        while (not count or sent < count) and not ended():
            try:
                line = await asyncio.wait_for(lines.get(), HEARTBEAT_S)
            except asyncio.TimeoutError:  # noqa: UP041 (a distinct class before Python 3.11)
                yield "\n"
                continue
            while not lines.empty() and (not count or sent + 1 < count):  # one write for all
                line += lines.get_nowait()
                sent += 1
            yield line
            sent += 1
            if any(part.startswith('{"error"') for part in line.splitlines()):
                return  # the echo ended with an error line
    finally:
        echo.stop()
