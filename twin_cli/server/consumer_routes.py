"""Routes of the world's consumers: a rosbag2 MCAP recording and a live Foxglove stream.

Kept apart from the world routes (`app.py`) so that each module holds one job; the consumers
themselves live in `twin_cli.record`.
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import APIRouter, Request

from twin_cli.server.holder import WorldDep
from twin_cli.server.models import FoxgloveBody, RecordBody

log = logging.getLogger("twin.server")
router = APIRouter()


def _consumers(request: Request) -> Any:
    """The server's recording and live stream (`twin_cli.record.service.Consumers`)."""
    state = request.app.state
    if getattr(state, "consumers", None) is None:
        from twin_cli.record.service import Consumers

        state.consumers = Consumers()
    return state.consumers


@router.post("/record", status_code=201)
def start_recording(body: RecordBody, request: Request, world: WorldDep) -> dict:
    """Record the world into a rosbag2 MCAP file on the server host (`twin record`)."""
    status = _consumers(request).record(
        world, body.path, rate=body.rate, entities=body.entities, duration=body.duration
    )
    log.info("recording to %s at %g Hz", body.path, body.rate)
    return status


@router.get("/record")
def recording_status(request: Request) -> dict:
    return _consumers(request).record_status()


@router.delete("/record")
def stop_recording(request: Request) -> dict:
    status = _consumers(request).stop_recording()
    log.info("recording %s closed: %d samples", status["path"], status["samples"])
    return status


@router.post("/foxglove", status_code=201)
def start_foxglove(body: FoxgloveBody, request: Request, world: WorldDep) -> dict:
    """Stream the world's topics over the Foxglove WebSocket protocol (`twin foxglove`)."""
    reply = _consumers(request).stream(world, port=body.port, host=body.host, rate=body.rate)
    log.info("Foxglove stream on %s", reply["url"])
    return reply


@router.delete("/foxglove")
def stop_foxglove(request: Request) -> dict:
    return _consumers(request).stop_stream()
