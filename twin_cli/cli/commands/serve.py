"""`twin serve`: run a world server in the foreground, like gzserver (the one server-side command).

Kept apart from the client commands in `world.py` so that those never reach mujoco or fastapi.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from twin_cli.cli.options import CoacdCpuLimitOpt, PackageOpt, WorldOpt, usage_errors
from twin_cli.server.autosave import DEFAULT_INTERVAL_S


def serve(
    world_file: Annotated[
        Path | None,
        typer.Argument(
            help="An SDF world (.sdf, .world), an MJCF scene (.xml) or a `twin save` file."
        ),
    ] = None,
    world: WorldOpt = "default",
    rate: Annotated[float | None, typer.Option(help="Real-time update rate (Hz); 0 = max.")] = None,
    step: Annotated[float | None, typer.Option(help="Physics step (s) (default 0.001).")] = None,
    paused: Annotated[bool, typer.Option("--paused", help="Start paused.")] = False,
    tcp: Annotated[
        str | None, typer.Option(help="Also listen on HOST:PORT (loopback if only PORT), token.")
    ] = None,
    background: Annotated[bool, typer.Option("--background", hidden=True)] = False,
    record: Annotated[
        Path | None, typer.Option(help="Record a rosbag2 MCAP file (100 Hz) from the start.")
    ] = None,
    foxglove: Annotated[
        int | None,
        typer.Option(help="Stream live to Foxglove on 127.0.0.1:PORT (Foxglove's is 8765)."),
    ] = None,
    autosave: Annotated[
        float,
        typer.Option(
            min=0.0,
            envvar="TWIN_AUTOSAVE",
            help="Save the world every SECONDS for `twin load --last` (0: off).",
        ),
    ] = DEFAULT_INTERVAL_S,
    no_autosave: Annotated[
        bool, typer.Option("--no-autosave", help="Do not autosave (same as --autosave 0).")
    ] = False,
    view: Annotated[
        bool, typer.Option("--view", help="Serve MuJoCo's web viewer on 127.0.0.1 too.")
    ] = False,
    package: PackageOpt = None,
    ros: Annotated[
        bool,
        typer.Option(
            "--ros", help="Publish on the ROS 2 graph over DDS (loopback only; ROS_DOMAIN_ID)."
        ),
    ] = False,
    ros_interface: Annotated[
        str | None,
        typer.Option(help="With --ros: use this interface (address or name), not loopback."),
    ] = None,
    ros_services: Annotated[
        bool,
        typer.Option(
            "--ros-services",
            help="With --ros: answer /spawn_entity and /delete_entity (any DDS peer may call).",
        ),
    ] = False,
    ros_distro: Annotated[
        str | None,
        typer.Option(
            help="With --ros: the nodes' ROS 2 distribution (humble, jazzy, ...), the form of "
            "the GIDs `ros2 node list` reads. Default: $ROS_DISTRO, else jazzy."
        ),
    ] = None,
    coacd_cpu_limit: CoacdCpuLimitOpt = None,
) -> None:
    """Run a world server in the foreground (like gzserver); Ctrl-C or SIGTERM ends it.

    An SDF world's `model://NAME` is found with `--package NAME=PATH`, then GAZEBO_MODEL_PATH /
    GZ_SIM_RESOURCE_PATH, then the directories above the file. `--coacd-cpu-limit` applies to
    the world file's models and to every spawn that does not give its own.
    """
    import os

    from converters.collision.plan import CPU_LIMIT_ENV
    from twin_cli.cli.pairs import parse_pairs
    from twin_cli.server.process import ServeOptions
    from twin_cli.server.process import serve as run_server

    with usage_errors():
        packages = parse_pairs(package, "=", "--package")
        if coacd_cpu_limit is not None and not 0 < coacd_cpu_limit < float("inf"):
            raise typer.BadParameter(
                "give a positive number of CPU seconds", param_hint="--coacd-cpu-limit"
            )
    if coacd_cpu_limit is not None:  # read by every conversion in this server (and its children)
        os.environ[CPU_LIMIT_ENV] = repr(coacd_cpu_limit)
    if ros_distro is not None:  # the server's bridge reads ROS_DISTRO as the other variables
        from twin_cli.ros.distro import distro_from

        os.environ["ROS_DISTRO"] = distro_from(os.environ, ros_distro)
    opts = ServeOptions(
        world,
        str(world_file) if world_file else None,
        rate,
        step,
        paused,
        tcp,
        background,
        str(record) if record else None,
        foxglove,
        view=view,
        autosave=0.0 if no_autosave else autosave,
        package_paths=packages or None,
        ros=ros,
        ros_interface=ros_interface,
        ros_services=ros_services,
    )
    run_server(opts)


def register(app: typer.Typer) -> None:
    """Add `twin serve` to the `twin` app."""
    app.command("serve")(serve)
