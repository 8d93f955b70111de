"""Routes of the controllers: drive a diff-drive base and read its odometry (`twin drive`, `odom`).

The lesson's `/cmd_vel` and `/odom` over HTTP. The controllers live beside the world
(`twin_cli.control`), run in sim time between batches, and act through the engine's API.
"""

from __future__ import annotations

from fastapi import APIRouter
from pydantic import BaseModel, Field

from twin_cli.server.holder import WorldDep

router = APIRouter()


class DriveRequest(BaseModel):
    """geometry_msgs/Twist's forward and yaw speeds, held for `duration` [s] of sim time."""

    linear: float = Field(0.0, description="forward speed [m/s] (Twist linear.x)")
    angular: float = Field(0.0, description="yaw rate [rad/s] (Twist angular.z)")
    duration: float | None = Field(
        None, description="sim seconds before the wheels stop (default: until replaced)"
    )


@router.post("/entities/{name}/drive")
def drive_entity(name: str, body: DriveRequest, world: WorldDep) -> dict:
    """Commands the entity's diff drive; errors: unknown entity, no drive plugin, not finite."""
    from twin_cli.control import drive

    return drive(world, name, body.linear, body.angular, body.duration)


@router.get("/entities/{name}/odom")
def entity_odometry(name: str, world: WorldDep) -> dict:
    """nav_msgs/Odometry's content: pose (odom frame) and twist (base frame)."""
    from twin_cli.control import odometry

    return odometry(world, name)
