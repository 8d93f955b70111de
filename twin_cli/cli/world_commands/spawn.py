"""`twin spawn`: a FILE, stdin or `--xml` text as one spawn request, at one pose or many.

Client-side only; `SpawnRequest` (with hashlib) is imported when a spawn runs, not when the
commands are registered for another one.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from twin_cli.cli import pairs
from twin_cli.cli.output import Output
from twin_cli.cli.params import (
    ARG,
    COACD_CPU_LIMIT,
    FIXED_BASE,
    JOINT,
    JSON,
    PACKAGE,
    POSE,
    POSE_KEYS,
    WORLD,
    Vec3,
)
from twin_cli.cli.registry import Arg, Opt, command, flag
from twin_cli.cli.world_client import connect_world

if TYPE_CHECKING:
    from twin_cli.spawn_request import SpawnRequest


def spawn_pose(
    position: Vec3, rpy: Vec3, quat: tuple[float, float, float, float] | None
) -> dict[str, Any]:
    """The request pose: position and roll-pitch-yaw, or position and a quaternion (x, y, z, w).

    Raises:
        BadOption: both a rotation (-R/-P/-Y) and --quat, or a zero quaternion.
    """
    pose: dict[str, Any] = dict(zip(POSE_KEYS[:3], position, strict=True))
    if quat is None:
        return pose | dict(zip(POSE_KEYS[3:], rpy, strict=True))
    if any(rpy):
        raise pairs.BadOption("give -R/-P/-Y or --quat X Y Z W, not both")
    if sum(v * v for v in quat) < 1e-12:
        raise pairs.BadOption("--quat must not be zero; give a unit quaternion X Y Z W")
    return pose | {"quat": list(quat)}


def spawn_request(
    file: Path | None,
    xml: str | None,
    arg: list[str] | None,
    package: list[str] | None,
    joint: list[str] | None,
    on_ground: bool,
    repair_inertia: bool,
    strict: bool = False,
    fixed_base: bool = False,
    coacd_cpu_limit: float | None = None,
) -> SpawnRequest:
    """The spawn request of a command line: a FILE, `-` (stdin) or `--xml` text, and options.

    Raises:
        BadOption: neither or both of FILE and --xml, or an option that does not parse.
    """
    if (file is None) == (xml is None):
        raise pairs.BadOption("give a FILE (or - for stdin) or --xml TEXT, not both or neither")
    from twin_cli.spawn_request import SpawnRequest

    if file is not None and str(file) == "-":
        file, xml = None, sys.stdin.read()
    inputs = pairs.source_inputs(arg, package)
    return SpawnRequest(
        source=None if file is None else str(file),
        xml=xml,
        base_dir=str(Path.cwd()) if xml is not None else None,
        args=inputs.get("args") or {},
        package_paths=inputs.get("package_paths") or {},
        joints=pairs.joint_positions(joint) or {},
        on_ground=on_ground,
        repair_inertia=repair_inertia,
        strict=strict,
        fixed_base=fixed_base,
        coacd_cpu_limit=coacd_cpu_limit,
    )


@command(
    "spawn",
    Arg("file", "URDF, xacro, SDF or MJCF file; - reads it from stdin.", Path, False),
    *POSE,
    Opt(("--name",), "name", "Entity name (default: the robot's).", str),
    ARG,
    PACKAGE,
    flag("--on-ground", dest="on_ground", help="Rest on the ground."),
    JOINT,
    WORLD,
    JSON,
    Opt(("--xml",), "xml", "The description as text (URDF or SDF), instead of FILE.", str),
    Opt(
        ("--quat",),
        "quat",
        "Orientation as a quaternion X Y Z W, instead of -R -P -Y.",
        float,
        nargs=4,
    ),
    Opt(
        ("--at",),
        "at",
        "Spawn one entity per pose X,Y[,Z[,YAW]] (repeat it), in one request; "
        "named NAME_0, NAME_1, … All or nothing.",
        str,
        multiple=True,
    ),
    Opt(("--names",), "names", "Names of the --at entities, comma-separated.", str),
    flag("--view", dest="view", help="Also show the world in the web viewer (twin view)."),
    flag(
        "--repair-inertia",
        dest="repair_inertia",
        help="Bound non-physical inertias instead of failing.",
    ),
    flag(
        "--strict",
        dest="strict",
        help="Refuse tags naming a missing link or joint, and visuals whose mesh is "
        "missing, instead of leaving them out with a warning (as Gazebo does).",
    ),
    flag(
        "--drop-dangling",
        dest="drop_dangling",
        help="Leave those out with a warning: the default (kept for older scripts).",
    ),
    FIXED_BASE,
    COACD_CPU_LIMIT,
    help="Spawn a robot or model; prints its name once it exists in the world.\n\n"
    "Packages (`$(find)`, `package://`, `model://`) resolve with this shell's ROS_PACKAGE_PATH,\n"
    "AMENT_PREFIX_PATH, GAZEBO_MODEL_PATH and GZ_SIM_RESOURCE_PATH, as `twin convert` would.",
)
def spawn(
    *,
    file: Path | None,
    x: float,
    y: float,
    z: float,
    roll: float,
    pitch: float,
    yaw: float,
    name: str | None,
    arg: list[str] | None,
    package: list[str] | None,
    on_ground: bool,
    joint: list[str] | None,
    world: str,
    json: bool,
    xml: str | None = None,
    quat: tuple[float, float, float, float] | None = None,
    at: list[str] | None = None,
    names: str | None = None,
    view: bool = False,
    repair_inertia: bool = False,
    strict: bool = False,
    drop_dangling: bool = False,
    fixed_base: bool = False,
    coacd_cpu_limit: float | None = None,
) -> None:
    """Spawn from a file, from stdin (`-`) or from `--xml` text (SpawnEntity's `-stdin`/`xml`).

    With `--at` (repeated), one entity per pose in one request, all or none; `view` also shows
    the world in the web viewer (its URL on stderr). `drop_dangling` is the default behaviour
    and is accepted for older scripts; `strict` refuses what it leaves out.
    """
    if name is not None:
        from twin_cli.names import name_message, name_problem

        if name_problem(name) is not None:
            from twin_cli.errors import InvalidRequestError

            raise InvalidRequestError("--name", name_message(name), "nothing was spawned")
    many = bool(at) or names is not None
    if many:
        poses, listed = batch_placements(at or [], names, (x, y), (z, roll, pitch, yaw), quat)
    else:
        pose = spawn_pose((x, y, z), (roll, pitch, yaw), quat)
    request = spawn_request(
        file,
        xml,
        arg,
        package,
        joint,
        on_ground,
        repair_inertia,
        strict,
        fixed_base,
        coacd_cpu_limit,
    )
    with connect_world(world, start=True) as c, _progress(world, file, json):
        if many:
            results = c.spawn_batch(request, poses=poses, names=listed, base=name)
        else:
            results = [c.spawn(request, name=name, pose=pose)]
        if view:
            url = c.request("POST", "/view", body={})["url"]
            sys.stderr.write(f"twin: viewer on {url}\n")
    _report(results if many else results[0], json)


def _progress(world: str, file: Path | None, json: bool) -> Any:
    """The world's conversion stage on a terminal while the spawn waits (nothing with --json)."""
    from contextlib import nullcontext

    from twin_cli.cli.conversion_progress import WorldProgress

    if json:
        return nullcontext()
    source = None if file is None or str(file) == "-" else str(file.expanduser().resolve())
    return WorldProgress(world, source)


def batch_placements(
    at: list[str],
    names: str | None,
    xy: tuple[float, float],
    z_rpy: tuple[float, float, float, float],
    quat: tuple[float, float, float, float] | None,
) -> tuple[list[dict[str, Any]], list[str] | None]:
    """`--at X,Y[,Z[,YAW]]` poses (z, roll, pitch, yaw from -z -R -P -Y) and `--names`.

    Raises:
        BadOption: no --at for --names, or -x/-y/--quat given with --at.
    """
    from twin_cli.cli import batch_poses

    if not at:
        raise pairs.BadOption("--names needs one --at X,Y[,Z[,YAW]] per name")
    if quat is not None or any(xy):
        raise pairs.BadOption("give positions with --at X,Y[,Z[,YAW]], not -x/-y/--quat")
    poses = [batch_poses.parse_at(text, *z_rpy) for text in at]
    return poses, batch_poses.parse_names(names, len(poses))


def _report(results: dict | list[dict], json: bool) -> None:
    """The spawned names (warnings on stderr), or the replies as JSON."""
    out = Output(json)
    if json:
        out.data(results)
        return
    for result in results if isinstance(results, list) else [results]:
        for warning in result.get("warnings") or []:
            sys.stderr.write(f"twin: warning: {warning}\n")
        out.line(result["name"])
