"""Routes of the world's ROS 2 bridge (`twin ros start|stop|status`, `twin serve --ros`).

Kept apart from the world routes (`app.py`); the bridge lives in `twin_cli.ros` and is imported
only when a route asks for it (cyclonedds loads with it).
"""

from __future__ import annotations

import logging
from typing import Any

from fastapi import APIRouter, Request

from twin_cli.server.holder import WorldDep
from twin_cli.server.models import RosBody

log = logging.getLogger("twin.server")
router = APIRouter()


def ros_service(state: Any) -> Any:
    """The server's ROS 2 bridge service (`twin_cli.ros.RosService`), made on first use."""
    if getattr(state, "ros", None) is None:
        from twin_cli.ros import RosService

        state.ros = RosService()
    return state.ros


@router.post("/ros", status_code=201)
def start_ros(body: RosBody, request: Request, world: WorldDep) -> dict:
    """Publish the world's topics on the ROS 2 graph and take its cmd_vel (`twin ros start`)."""
    service = ros_service(request.app.state)
    status = service.start(
        world, interface=body.interface, environment=body.environment, services=body.services
    )
    log.info("ROS 2 bridge started: %s", status["scope"])
    return status


@router.get("/ros")
def ros_status(request: Request) -> dict:
    return ros_service(request.app.state).status()


@router.delete("/ros")
def stop_ros(request: Request) -> dict:
    status = ros_service(request.app.state).stop()
    log.info("ROS 2 bridge stopped")
    return status
