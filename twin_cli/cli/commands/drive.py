"""`twin drive` and `twin odom`: a diff-drive base's /cmd_vel and /odom, like the lesson's.

Client-side (no mujoco or numpy): the server's controller (`twin_cli.control`) runs the
robot's `libgazebo_ros_diff_drive.so` parameters in sim time; these commands send one request.
"""

from __future__ import annotations

import math
from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output


def drive(
    entity: Annotated[str, typer.Argument(help="The entity with a diff-drive plugin.")],
    linear: Annotated[float, typer.Option("--linear", help="Forward speed, m/s.")] = 0.0,
    angular: Annotated[float, typer.Option("--angular", help="Yaw rate, rad/s.")] = 0.0,
    duration: Annotated[
        float | None,
        typer.Option("-d", "--duration", help="Sim seconds, then the wheels stop (default: hold)."),
    ] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Drive a diff-drive robot at a forward speed and yaw rate (geometry_msgs/Twist)."""
    from twin_cli.errors import InvalidRequestError
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    for what, value in (("linear", linear), ("angular", angular), ("duration", duration)):
        if value is not None and not math.isfinite(value):
            raise InvalidRequestError(f"drive {what}", f"{value} is not finite", "give a number")
    body = {"linear": linear, "angular": angular, "duration": duration}
    with connect(world) as client:
        reply = client.request("POST", f"/entities/{path_segment(entity)}/drive", body=body)
    out = Output(json)
    if json:
        out.data(reply)
        return
    held = "until replaced" if duration is None else f"for {duration:g} s"
    out.line(f"{entity}: v={linear:g} m/s, w={angular:g} rad/s {held} ({reply['plugin']})")


def odom(
    entity: Annotated[str, typer.Argument(help="The entity with a diff-drive plugin.")],
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print a diff-drive robot's odometry: pose and twist (nav_msgs/Odometry)."""
    from twin_cli.server.connection import connect
    from twin_cli.server.transport import path_segment

    with connect(world) as client:
        reply = client.request("GET", f"/entities/{path_segment(entity)}/odom")
    out = Output(json)
    if json:
        out.data(reply)
        return
    out.table(f"{entity} odometry ({reply['source']}) t={reply['time']:.3f} s", *_rows(reply))


def _rows(reply: dict[str, Any]) -> tuple[list[str], list[list[Any]]]:
    position, rpy = reply["pose"]["position"], reply["pose"]["rpy"]
    linear, angular = reply["twist"]["linear"], reply["twist"]["angular"]
    rows = [
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
