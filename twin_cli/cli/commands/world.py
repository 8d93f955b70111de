"""World commands (Gazebo's verbs) on a running world: stop, spawn, list, pose, gravity, stats...

Declarations only: each command's options and help, for Typer. What a command does lives in
`twin_cli.cli.world_actions`, which the fast path (`twin_cli.cli.fast`) calls with the same
options without importing Typer; `tests/test_cli_fast.py` holds the two to the same grammar.
This module and everything it imports stay client-side: no mujoco, numpy or fastapi (an import
contract in `make lint` holds it to that); `twin serve` lives in `serve.py`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from twin_cli.cli import world_actions as act
from twin_cli.cli.options import (
    ArgOpt,
    JointOpt,
    JsonOpt,
    PackageOpt,
    PitchOpt,
    RollOpt,
    WorldOpt,
    XOpt,
    YawOpt,
    YOpt,
    ZOpt,
    usage_errors,
)

NameArg = Annotated[str, typer.Argument(help="Entity name (see `twin list`).")]
Vec3 = tuple[float, float, float]


def stop(world: WorldOpt = "default") -> None:
    """Stop the world's server (waits until its process has ended)."""
    act.stop(world=world)


def spawn(
    file: Annotated[
        Path | None, typer.Argument(help="URDF, xacro, SDF or MJCF file; - reads it from stdin.")
    ] = None,
    x: XOpt = 0.0,
    y: YOpt = 0.0,
    z: ZOpt = 0.0,
    roll: RollOpt = 0.0,
    pitch: PitchOpt = 0.0,
    yaw: YawOpt = 0.0,
    name: Annotated[str | None, typer.Option(help="Entity name (default: the robot's).")] = None,
    arg: ArgOpt = None,
    package: PackageOpt = None,
    on_ground: Annotated[bool, typer.Option("--on-ground", help="Rest on the ground.")] = False,
    joint: JointOpt = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
    xml: Annotated[
        str | None, typer.Option(help="The description as text (URDF or SDF), instead of FILE.")
    ] = None,
    quat: Annotated[
        tuple[float, float, float, float] | None,
        typer.Option(help="Orientation as a quaternion X Y Z W, instead of -R -P -Y."),
    ] = None,
    at: Annotated[
        list[str] | None,
        typer.Option(
            help="Spawn one entity per pose X,Y[,Z[,YAW]] (repeat it), in one request; "
            "named NAME_0, NAME_1, … All or nothing."
        ),
    ] = None,
    names: Annotated[
        str | None, typer.Option(help="Names of the --at entities, comma-separated.")
    ] = None,
    view: Annotated[
        bool, typer.Option("--view", help="Also show the world in the web viewer (twin view).")
    ] = False,
    repair_inertia: Annotated[
        bool,
        typer.Option("--repair-inertia", help="Bound non-physical inertias instead of failing."),
    ] = False,
) -> None:
    """Spawn a robot or model; prints its name once it exists in the world.

    Packages (`$(find)`, `package://`, `model://`) resolve with this shell's ROS_PACKAGE_PATH,
    AMENT_PREFIX_PATH, GAZEBO_MODEL_PATH and GZ_SIM_RESOURCE_PATH, as `twin convert` would.
    """
    with usage_errors():
        act.spawn(
            file=file,
            x=x,
            y=y,
            z=z,
            roll=roll,
            pitch=pitch,
            yaw=yaw,
            name=name,
            arg=arg,
            package=package,
            on_ground=on_ground,
            joint=joint,
            world=world,
            json=json,
            xml=xml,
            quat=quat,
            at=at,
            names=names,
            view=view,
            repair_inertia=repair_inertia,
        )


def delete(name: NameArg, world: WorldOpt = "default") -> None:
    """Delete an entity."""
    act.delete(name=name, world=world)


def list_(world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """List the entities in the world."""
    act.list_(world=world, json=json)


def pose(
    name: NameArg,
    set_: Annotated[
        tuple[float, float, float, float, float, float] | None,
        typer.Option("--set", help="Move it: X Y Z (m) ROLL PITCH YAW (rad)."),
    ] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
    quat: Annotated[
        bool, typer.Option("--quat", help="Print x y z qx qy qz qw (a quaternion).")
    ] = False,
) -> None:
    """Print an entity's pose as `x y z roll pitch yaw` (or move it with --set)."""
    act.pose(name=name, set_=set_, world=world, json=json, quat=quat)


def joints(name: NameArg, world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """Print an entity's joint positions, velocities and efforts."""
    act.joints(name=name, world=world, json=json)


def push(
    name: NameArg,
    force: Annotated[Vec3, typer.Option(help="Force FX FY FZ (N), world frame.")] = (0, 0, 0),
    torque: Annotated[Vec3, typer.Option(help="Torque TX TY TZ (N m).")] = (0, 0, 0),
    link: Annotated[str | None, typer.Option(help="Link to push (default: the root).")] = None,
    duration: Annotated[float, typer.Option(help="How long (s) of sim time.")] = 0.1,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Apply a force and torque to an entity for a while."""
    act.push(
        name=name, force=force, torque=torque, link=link, duration=duration, world=world, json=json
    )


def gravity(
    earth: Annotated[bool, typer.Option("--earth", help="(0, 0, -9.81)")] = False,
    moon: Annotated[bool, typer.Option("--moon", help="(0, 0, -1.62)")] = False,
    mars: Annotated[bool, typer.Option("--mars", help="(0, 0, -3.71)")] = False,
    zero: Annotated[bool, typer.Option("--zero", help="(0, 0, 0)")] = False,
    set_: Annotated[Vec3 | None, typer.Option("--set", help="X Y Z (m/s^2).")] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print the gravity vector, or set it from a preset or --set X Y Z."""
    with usage_errors():
        act.gravity(earth=earth, moon=moon, mars=mars, zero=zero, set_=set_, world=world, json=json)


def physics(
    step: Annotated[float | None, typer.Option(help="Physics step (s).")] = None,
    rate: Annotated[float | None, typer.Option(help="Real-time update rate (Hz); 0 = max.")] = None,
    iterations: Annotated[int | None, typer.Option(help="Solver iterations.")] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
    threads: Annotated[
        int | None, typer.Option(help="MuJoCo engine threads, 1-64 (default 1: no pool).")
    ] = None,
    sleep: Annotated[
        bool, typer.Option("--sleep", help="Let resting robots sleep (off by default).")
    ] = False,
    no_sleep: Annotated[bool, typer.Option("--no-sleep", help="Keep every robot awake.")] = False,
    sleep_tolerance: Annotated[
        float | None, typer.Option(help="Speed (m/s) under which a robot may sleep.")
    ] = None,
) -> None:
    """Print the physics settings, or change step, rate, iterations, threads or sleeping."""
    act.physics(
        step=step, rate=rate, iterations=iterations, world=world, json=json,
        threads=threads, sleep=sleep, no_sleep=no_sleep, sleep_tolerance=sleep_tolerance,
    )  # fmt: skip


def pause(world: WorldOpt = "default") -> None:
    """Pause the simulation."""
    act.pause(world=world)


def resume(world: WorldOpt = "default") -> None:
    """Resume the simulation."""
    act.resume(world=world)


def step(
    n: Annotated[int, typer.Argument(min=1, help="Number of steps.")] = 1,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Advance the simulation N steps (also while paused)."""
    act.step(n=n, world=world, json=json)


def reset(
    time_only: Annotated[bool, typer.Option("--time-only", help="Only reset time.")] = False,
    world: WorldOpt = "default",
) -> None:
    """Reset the world (entities to their spawn poses, time to 0), or only its time."""
    act.reset(time_only=time_only, world=world)


def stats(
    duration: Annotated[
        float | None, typer.Option("-d", "--duration", help="Seconds to run (default: forever).")
    ] = None,
    plot: Annotated[bool, typer.Option("-p", "--plot", help="Comma-separated values.")] = False,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print `Factor[..] SimTime[..] RealTime[..] Paused[..]` about five times a second."""
    act.stats(duration=duration, plot=plot, world=world, json=json)


def save(
    file: Annotated[Path, typer.Argument(help="Where to write the world.")],
    world: WorldOpt = "default",
) -> None:
    """Save the world (entities, state, physics) to a file `twin load` reads."""
    act.save(file=file, world=world)


def load(
    file: Annotated[Path | None, typer.Argument(help="A file written by `twin save`.")] = None,
    world: WorldOpt = "default",
    last: Annotated[
        bool, typer.Option("--last", help="The world's last autosave (after a crash).")
    ] = False,
) -> None:
    """Replace the running world by one saved with `twin save` (starts the world if none runs)."""
    with usage_errors():
        act.load(file=file, world=world, last=last)


def logs(
    lines: Annotated[int | None, typer.Option("-n", "--lines", help="Only the last N.")] = None,
    world: WorldOpt = "default",
) -> None:
    """Print the world server's log file."""
    act.logs(lines=lines, world=world)


COMMANDS = {
    "stop": stop,
    "spawn": spawn,
    "delete": delete,
    "list": list_,
    "pose": pose,
    "joints": joints,
    "push": push,
    "gravity": gravity,
    "physics": physics,
    "pause": pause,
    "resume": resume,
    "step": step,
    "reset": reset,
    "stats": stats,
    "save": save,
    "load": load,
    "logs": logs,
}


def register(app: typer.Typer) -> None:
    """Add the world commands to the `twin` app."""
    for name, function in COMMANDS.items():
        app.command(name)(function)
