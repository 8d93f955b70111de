"""`twin ros start|stop|status`: a running world on the live ROS 2 graph (over DDS).

Client-side (no mujoco, numpy or cyclonedds here): the server runs the DDS participant
(`twin_cli.ros`); this side only asks. The scope is the ROS_DOMAIN_ID and
discovery variables as this shell has them (sent with the request), loopback only unless
`--interface` is given; ROS_DISTRO (or `--distro`) shapes the node's GIDs for that distribution.
"""

from __future__ import annotations

import os
from typing import Annotated, Any

import typer

from twin_cli.cli.options import JsonOpt, WorldOpt
from twin_cli.cli.output import Output
from twin_cli.ros.distro import distro_from

SCOPE_VARIABLES = (
    "ROS_DOMAIN_ID",
    "ROS_AUTOMATIC_DISCOVERY_RANGE",
    "ROS_STATIC_PEERS",
    "ROS_LOCALHOST_ONLY",
    "ROS_DISTRO",
)
app = typer.Typer(
    help="Publish a running world's topics on the ROS 2 graph and take its cmd_vel "
    "(`twin ros start`); `twin ros stop` leaves the graph.",
    no_args_is_help=True,
)


def start(
    interface: Annotated[
        str | None,
        typer.Option(help="Use this network interface (address or name), not loopback only."),
    ] = None,
    services: Annotated[
        bool,
        typer.Option(
            "--services",
            help="Also answer gazebo_ros' /spawn_entity and /delete_entity: every DDS peer in "
            "the scope may then change the world (ROS 2 has no access control without SROS2).",
        ),
    ] = False,
    distro: Annotated[
        str | None,
        typer.Option(
            help="The nodes' ROS 2 distribution (humble, jazzy, ...): the form of the GIDs "
            "`ros2 node list` reads. Default: $ROS_DISTRO, else jazzy."
        ),
    ] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Join the ROS 2 graph: /clock, /tf, /tf_static and each entity's topics out; cmd_vel and
    controller commands in (gazebo_ros' entity services with --services)."""
    environment = ros_environment()
    if distro is not None:
        environment["ROS_DISTRO"] = distro_from(environment, distro, "--distro")
    body: dict[str, Any] = {"environment": environment, "services": services}
    if interface is not None:
        body["interface"] = interface
    _show(_ask(world, "POST", body), json, "publishing")


def stop(world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """Leave the ROS 2 graph."""
    _show(_ask(world, "DELETE"), json, "stopped")


def status(world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """What the bridge publishes, where, and the commands it took."""
    _show(_ask(world, "GET"), json, "publishing")


def ros_environment() -> dict[str, str]:
    """This shell's ROS 2 scope variables: the bridge joins the graph this shell's nodes see."""
    return {k: v for k, v in os.environ.items() if k in SCOPE_VARIABLES}


def _ask(world: str, method: str, body: dict | None = None) -> dict[str, Any]:
    from twin_cli.server.connection import connect

    with connect(world, start=False) as client:
        return client.request(method, "/ros", body=body)


def _show(reply: dict[str, Any], json: bool, verb: str) -> None:
    out = Output(json)
    if json:
        out.data(reply)
        return
    out.line(f"{verb}: {reply['scope']}, {reply['samples']} samples at {reply['rate']:g} Hz")
    if reply["inputs"]:
        out.line(f"reading: {', '.join(reply['inputs'])} ({reply['commands']} commands taken)")
    if reply.get("services"):
        calls = reply.get("service_calls", 0)
        out.line(
            f"services: {', '.join(reply['services'])} ({calls} calls answered; any DDS peer "
            "in this scope may call them)"
        )
    else:
        out.line("services: none (entity services only with `twin ros start --services`)")


def register(parent: typer.Typer) -> None:
    """Adds `ros` (start, stop, status)."""
    app.command("start")(start)
    app.command("stop")(stop)
    app.command("status")(status)
    parent.add_typer(app, name="ros")
