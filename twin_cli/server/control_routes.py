"""Routes of the controllers: joint commands, modes and trajectories (`twin command`, `joints`,
`trajectory`), and the diff drive's `/cmd_vel` and `/odom` (`twin drive`, `twin odom`).

The world's old single-joint `/entities/{name}/command` stays as it was (clipping instead of
refusing). The controllers live beside the world (`twin_cli.control`), run in sim time between
batches, and act through the engine's API.
"""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter
from pydantic import BaseModel, Field

from twin_cli.physical_ranges import CommandValue
from twin_cli.server.holder import WorldDep
from twin_cli.server.models import Body

router = APIRouter()


class CommandsBody(Body):
    """Targets by joint name, in one mode; refused as a whole if any is outside its limits."""

    mode: Literal["position", "velocity", "effort"] = "position"
    targets: dict[str, CommandValue]


class PointBody(Body):
    """One trajectory_msgs/JointTrajectoryPoint; time_from_start in seconds."""

    positions: list[CommandValue]
    velocities: list[CommandValue] | None = None
    accelerations: list[CommandValue] | None = None
    time_from_start: Annotated[float, Field(ge=0.0, le=1e7, allow_inf_nan=False)] | None = None


class TrajectoryBody(Body):
    """A trajectory_msgs/JointTrajectory and the controller's update rate [Hz]."""

    joint_names: list[str]
    points: list[PointBody]
    rate: Annotated[float, Field(gt=0.0, le=10000.0)] = 100.0


@router.post("/entities/{name}/commands")
def commands(name: str, body: CommandsBody, world: WorldDep) -> dict:
    from twin_cli.control import release_joints

    with world.lock:  # no drive update between the command and the drive's stop
        done = world.command_joints(name, dict(body.targets), mode=body.mode)
        stopped = release_joints(world, name, list(body.targets))
        rows = world.joint_commands(name)
    passive = [j for j in body.targets if rows.get(j, {}).get("source") == "passive"]
    notes = [
        f"joint [{j}] has no control tag or drive plugin: passive in Gazebo, driven by twin's "
        f"motor at this {body.mode} command"
        for j in passive
    ]
    notes += stopped
    return {
        "commanded": name,
        "mode": body.mode,
        "joints": [c.actuator for c in done],
        "notes": notes,
    }


@router.get("/entities/{name}/control")
def control(name: str, world: WorldDep) -> list[dict]:
    """Each actuated joint: mode, target, position, velocity, effort, modes, gains, limits."""
    with world.lock:
        states = {s.name: s for s in world.joint_states(name)}
        rows = world.joint_commands(name)
    return [
        {
            "name": joint,
            **row,
            "position": states[joint].position,
            "velocity": states[joint].velocity,
            "effort": states[joint].effort,
        }
        for joint, row in rows.items()
        if joint in states
    ]


@router.post("/entities/{name}/trajectory")
def trajectory(name: str, body: TrajectoryBody, world: WorldDep) -> dict:
    from twin_cli.control import follow_trajectory, trajectory_from_dict

    doc = body.model_dump(exclude={"rate"})
    follower = follow_trajectory(world, name, trajectory_from_dict(doc), body.rate)
    return follower.report.to_dict()


@router.get("/entities/{name}/trajectory")
def trajectory_status(name: str, world: WorldDep) -> dict:
    from twin_cli.control import tracking_report
    from twin_cli.errors import InvalidRequestError

    world.joint_states(name)  # unknown entity: the usual error
    report = tracking_report(world, name)
    if report is None:
        raise InvalidRequestError(
            f"trajectory of [{name}]", "none was sent", "send one with twin trajectory"
        )
    return report


class DriveRequest(BaseModel):
    """geometry_msgs/Twist's speeds (or a steered base's angle or curvature), held for
    `duration` [s] of sim time."""

    linear: CommandValue = Field(0.0, description="forward speed [m/s] (Twist linear.x)")
    angular: CommandValue = Field(0.0, description="yaw rate [rad/s] (Twist angular.z)")
    lateral: CommandValue = Field(0.0, description="sideways speed [m/s] (holonomic bases)")
    steering: CommandValue | None = Field(
        None, description="bicycle steering angle [rad] (steered)"
    )
    curvature: CommandValue | None = Field(None, description="path curvature [1/m] (steered bases)")
    duration: float | None = Field(
        None, description="sim seconds before the wheels stop (default: until replaced)"
    )


@router.post("/entities/{name}/drive")
def drive_entity(name: str, body: DriveRequest, world: WorldDep) -> dict:
    """Commands the entity's drive; errors: unknown entity, no drive plugin, not finite."""
    from twin_cli.control import drive

    return drive(
        world,
        name,
        body.linear,
        body.angular,
        body.duration,
        lateral=body.lateral,
        steering=body.steering,
        curvature=body.curvature,
    )


@router.get("/entities/{name}/odom")
def entity_odometry(name: str, world: WorldDep) -> dict:
    """nav_msgs/Odometry's content: pose (odom frame) and twist (base frame)."""
    from twin_cli.control import odometry

    return odometry(world, name)
