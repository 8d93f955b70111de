"""World commands (Gazebo's verbs) on a running world: stop, spawn, list, pose, gravity, stats...

Thin: each command parses its options, makes one client call and hands the reply to `Output`.
This module and everything it imports stay client-side: no mujoco, numpy or fastapi (an import
contract in `make lint` holds it to that); `twin serve` lives in `serve.py`.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Annotated

import typer

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
    joint_positions,
    source_inputs,
)
from twin_cli.cli.output import Output

NameArg = Annotated[str, typer.Argument(help="Entity name (see `twin list`).")]
POSE_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")


def _connect(world: str, *, start: bool = True):
    """A client of the world's server; starts the server in the background if allowed."""
    from twin_cli.server import client

    return client.connect(world, start=start)


def _not_running(world: str) -> typer.Exit:
    """gz's readiness-probe wording on stderr, exit code 1 (scripts grep for it)."""
    sys.stderr.write("An instance of twin is not running.\n")
    return typer.Exit(1)


def _pose_text(pose: dict) -> str:
    """`x y z roll pitch yaw` as `gz model -p` prints it (rounding first: no `-0.000000`)."""
    return " ".join(f"{round(float(pose[k]), 6) + 0.0:.6f}" for k in POSE_KEYS)


def stop(world: WorldOpt = "default") -> None:
    """Stop the world's server (waits until its process has ended)."""
    from twin_cli.errors import NotRunningError
    from twin_cli.server import client

    try:
        pid = client.stop(world)
    except NotRunningError:
        raise _not_running(world) from None
    sys.stderr.write(f"twin: stopped world [{world}] (pid {pid})\n")


def spawn(
    file: Annotated[Path, typer.Argument(help="URDF, xacro or MJCF file.")],
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
) -> None:
    """Spawn a robot; prints its name once it exists in the world."""
    inputs = source_inputs(arg, package)
    joints = joint_positions(joint)
    pose = dict(zip(POSE_KEYS, (x, y, z, roll, pitch, yaw), strict=True))
    with _connect(world) as c:
        result = c.spawn(file, name=name, pose=pose, on_ground=on_ground, joints=joints, **inputs)
    out = Output(json)
    if json:
        out.data(result)
        return
    for warning in result.get("warnings") or []:
        sys.stderr.write(f"twin: warning: {warning}\n")
    out.line(result["name"])


def delete(name: NameArg, world: WorldOpt = "default") -> None:
    """Delete an entity."""
    with _connect(world) as c:
        c.delete(name)


def list_(world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """List the entities in the world."""
    with _connect(world) as c:
        rows = c.entities()
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        "entities",
        ["name", "x", "y", "z", "joints", "source"],
        [[e["name"], *e["position"], e["n_joints"], e["source"]] for e in rows],
    )


def pose(
    name: NameArg,
    set_: Annotated[
        tuple[float, float, float, float, float, float] | None,
        typer.Option("--set", help="Move it: X Y Z (m) ROLL PITCH YAW (rad)."),
    ] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print an entity's pose as `x y z roll pitch yaw` (or move it with --set)."""
    with _connect(world) as c:
        if set_ is None:
            result = c.pose(name)
        else:
            result = c.set_pose(name, dict(zip(POSE_KEYS, set_, strict=True)))
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(_pose_text(result))


def joints(name: NameArg, world: WorldOpt = "default", json: JsonOpt = False) -> None:
    """Print an entity's joint positions, velocities and efforts."""
    with _connect(world) as c:
        rows = c.joints(name)
    out = Output(json)
    if json:
        out.data(rows)
        return
    out.table(
        f"joints of {name}",
        ["joint", "position", "velocity", "effort"],
        [[j["name"], j["position"], j["velocity"], j["effort"]] for j in rows],
    )


Vec3 = tuple[float, float, float]


def push(
    name: NameArg,
    force: Annotated[Vec3, typer.Option(help="Force FX FY FZ (N), world frame.")] = (0, 0, 0),
    torque: Annotated[Vec3, typer.Option(help="Torque TX TY TZ (N m).")] = (0, 0, 0),
    link: Annotated[str | None, typer.Option(help="Link to push (default: the root).")] = None,
    duration: Annotated[float, typer.Option(help="How long (s) of sim time.")] = 0.1,
    world: WorldOpt = "default",
) -> None:
    """Apply a force and torque to an entity for a while."""
    with _connect(world) as c:
        c.push(name, force, torque, link=link, duration=duration)


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
    presets = [
        p for p, on in (("earth", earth), ("moon", moon), ("mars", mars), ("zero", zero)) if on
    ]
    if len(presets) + (set_ is not None) > 1:
        raise typer.BadParameter("give one of --earth, --moon, --mars, --zero or --set")
    with _connect(world) as c:
        if presets:
            result = c.set_gravity(preset=presets[0])
        elif set_ is not None:
            result = c.set_gravity(vector=set_)
        else:
            result = c.gravity()
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(" ".join(f"{v:g}" for v in result["gravity"]))


def physics(
    step: Annotated[float | None, typer.Option(help="Physics step (s).")] = None,
    rate: Annotated[float | None, typer.Option(help="Real-time update rate (Hz); 0 = max.")] = None,
    iterations: Annotated[int | None, typer.Option(help="Solver iterations.")] = None,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print the physics settings, or change step, rate or iterations."""
    changes = {
        k: v
        for k, v in (("timestep", step), ("rate", rate), ("iterations", iterations))
        if v is not None
    }
    with _connect(world) as c:
        result = c.set_physics(**changes) if changes else c.physics()
    out = Output(json)
    if json:
        out.data(result)
        return
    out.table("physics", ["setting", "value"], [[k, v] for k, v in result.items()])


def pause(world: WorldOpt = "default") -> None:
    """Pause the simulation."""
    with _connect(world) as c:
        c.pause()


def resume(world: WorldOpt = "default") -> None:
    """Resume the simulation."""
    with _connect(world) as c:
        c.resume()


def step(
    n: Annotated[int, typer.Argument(min=1, help="Number of steps.")] = 1,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Advance the simulation N steps (also while paused)."""
    from twin_cli.cli.stats_format import stats_line

    with _connect(world) as c:
        result = c.step(n)
    out = Output(json)
    if json:
        out.data(result)
    else:
        out.line(stats_line(result))


def reset(
    time_only: Annotated[bool, typer.Option("--time-only", help="Only reset time.")] = False,
    world: WorldOpt = "default",
) -> None:
    """Reset the world (entities to their spawn poses, time to 0), or only its time."""
    with _connect(world) as c:
        c.reset(time_only=time_only)


def stats(
    duration: Annotated[
        float | None, typer.Option("-d", "--duration", help="Seconds to run (default: forever).")
    ] = None,
    plot: Annotated[bool, typer.Option("-p", "--plot", help="Comma-separated values.")] = False,
    world: WorldOpt = "default",
    json: JsonOpt = False,
) -> None:
    """Print `Factor[..] SimTime[..] RealTime[..] Paused[..]` about five times a second."""
    from twin_cli.cli import stats_format as fmt
    from twin_cli.errors import NotRunningError

    try:
        c = _connect(world, start=False)
    except NotRunningError:
        raise _not_running(world) from None
    render = fmt.stats_json if json else fmt.stats_csv_row if plot else fmt.stats_line
    try:
        with c:
            if plot and not json:
                print(fmt.CSV_HEADER, flush=True)
            for tick in fmt.sample_times(time.monotonic(), duration):
                time.sleep(max(0.0, tick - time.monotonic()))
                print(render(c.stats()), flush=True)
    except NotRunningError:
        raise _not_running(world) from None
    except (KeyboardInterrupt, BrokenPipeError):
        return


def save(
    file: Annotated[Path, typer.Argument(help="Where to write the world.")],
    world: WorldOpt = "default",
) -> None:
    """Save the world (entities, state, physics) to a file `twin load` reads."""
    with _connect(world) as c:
        c.save(file)


def load(
    file: Annotated[Path, typer.Argument(help="A file written by `twin save`.")],
    world: WorldOpt = "default",
) -> None:
    """Replace the running world by one saved with `twin save`."""
    with _connect(world) as c:
        c.load(file)


def logs(
    lines: Annotated[int | None, typer.Option("-n", "--lines", help="Only the last N.")] = None,
    world: WorldOpt = "default",
) -> None:
    """Print the world server's log file."""
    from twin_cli.server import runtime

    paths = runtime.world_paths(world)
    if not paths.log.exists():
        sys.stderr.write(f"twin: no log for world [{world}] in {paths.directory}\n")
        raise typer.Exit(1)
    sys.stdout.write(runtime.log_tail(paths, lines))


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
