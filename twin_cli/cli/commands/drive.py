"""`twin drive` and `twin odom`: a mobile base's /cmd_vel and /odom, whatever drive it has.

Client-side (no mujoco or numpy): the server's controller (`twin_cli.control`) runs the robot's
drive plugin (diff drive, skid steer, Ackermann, tricycle, planar move, gz-sim's DiffDrive,
AckermannSteering, MecanumDrive) in sim time; these commands send one request.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output


def drive(
    entity: Annotated[str, typer.Argument(help="The entity with a drive plugin.")],
    linear: Annotated[float, typer.Option("--linear", help="Forward speed, m/s.")] = 0.0,
    angular: Annotated[float, typer.Option("--angular", help="Yaw rate, rad/s.")] = 0.0,
    lateral: Annotated[
        float,
        typer.Option(
            "--lateral", help="Sideways speed, m/s (planar move, mecanum, VelocityControl)."
        ),
    ] = 0.0,
    steering: Annotated[
        float | None,
        typer.Option("--steering", help="Steering angle, rad (Ackermann, tricycle)."),
    ] = None,
    curvature: Annotated[
        float | None,
        typer.Option("--curvature", help="Path curvature, 1/m (Ackermann, tricycle)."),
    ] = None,
    duration: Annotated[
        float | None,
        typer.Option("-d", "--duration", help="Sim seconds, then the wheels stop (default: hold)."),
    ] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Drive a mobile base: forward speed and yaw rate (geometry_msgs/Twist), or a steering
    angle or curvature for car-like bases."""
    from twin_cli.errors import InvalidRequestError
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    given = {
        "linear": linear,
        "angular": angular,
        "lateral": lateral,
        "steering": steering,
        "curvature": curvature,
        "duration": duration,
    }
    for what, value in given.items():
        if value is not None and not math.isfinite(value):
            raise InvalidRequestError(f"drive {what}", f"{value} is not finite", "give a number")
    with connect(world) as client:
        reply = client.request("POST", f"/entities/{path_segment(entity)}/drive", body=given)
    out = Output(json)
    if json:
        out.data(reply)
        return
    out.line(f"{entity}: {_command_text(reply)} {_held(duration)} ({reply['family']})")


def _held(duration: float | None) -> str:
    return "until replaced" if duration is None else f"for {duration:g} s"


def _command_text(reply: dict[str, Any]) -> str:
    parts = [f"v={reply['linear']:g} m/s"]
    if reply.get("lateral"):
        parts.append(f"vy={reply['lateral']:g} m/s")
    applied = reply.get("applied", {})
    if "steering_angle" in applied:
        parts.append(f"steering={applied['steering_angle']:.4g} rad")
        parts.append(f"w={applied['yaw_rate']:.4g} rad/s")
    else:
        parts.append(f"w={reply['angular']:g} rad/s")
    return ", ".join(parts)


def odom(
    entity: Annotated[str, typer.Argument(help="The entity with a drive plugin.")],
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print a base's odometry: pose and twist (nav_msgs/Odometry) with its frame names."""
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    with connect(world) as client:
        reply = client.request("GET", f"/entities/{path_segment(entity)}/odom")
    out = Output(json)
    if json:
        out.data(reply)
        return
    title = (
        f"{entity} odometry ({reply['source']}, {reply['odometry_frame']} -> "
        f"{reply['robot_base_frame']}) t={reply['time']:.3f} s"
    )
    out.table(title, *_rows(reply))


def _rows(reply: dict[str, Any]) -> tuple[list[str], list[list[Any]]]:
    position, rpy = reply["pose"]["position"], reply["pose"]["rpy"]
    linear, angular = reply["twist"]["linear"], reply["twist"]["angular"]
    rows = [
        ["frames (odometry, base)", reply["odometry_frame"], reply["robot_base_frame"], ""],
        ["position [m]", *(f"{v:.4f}" for v in position)],
        ["roll pitch yaw [rad]", *(f"{v:.4f}" for v in rpy)],
        ["linear [m/s]", *(f"{v:.4f}" for v in linear)],
        ["angular [rad/s]", *(f"{v:.4f}" for v in angular)],
    ]
    return ["", "x", "y", "z"], rows


def register(app: typer.Typer) -> None:
    """Adds `drive` and `odom`."""
    app.command("drive")(drive)
    app.command("odom")(odom)
