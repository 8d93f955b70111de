"""Parameters several commands share, declared once (Gazebo's names where Gazebo has them).

Plain declarations (`registry.Opt`, `registry.Arg`) that the world commands list in their
`command(...)` and that `options.annotation` turns into Typer's for the other command groups.
"""

from __future__ import annotations

from twin_cli.cli.registry import Arg, Opt, flag

WORLD_ENV = "TWIN_WORLD"
WORLD = Opt(
    ("--world",), "world", "Name of the world to talk to.", str, "default", envvar=WORLD_ENV
)
JSON = flag("--json", dest="json", help="Print machine-readable JSON.")
ARG = Opt(("--arg",), "arg", "xacro argument NAME:=VALUE (repeatable).", str, multiple=True)
PACKAGE = Opt(
    ("--package",), "package", "Package location NAME=PATH (repeatable).", str, multiple=True
)
JOINT = Opt(
    ("-J", "--joint"),
    "joint",
    "Initial joint position NAME=POS [rad or m] (repeatable; Gazebo's -J NAME POS).",
    str,
    multiple=True,
)
POSE_KEYS = ("x", "y", "z", "roll", "pitch", "yaw")  # a pose's keys in requests and replies
Vec3 = tuple[float, float, float]
POSE = tuple(
    Opt((short,), dest, f"Spawn {what}.", float, 0.0)
    for short, dest, what in zip(
        ("-x", "-y", "-z", "-R", "-P", "-Y"),
        POSE_KEYS,
        ("x [m]", "y [m]", "z [m]", "roll [rad]", "pitch [rad]", "yaw [rad]"),
        strict=True,
    )
)
FIXED_BASE = flag(
    "--fixed-base",
    dest="fixed_base",
    help="Weld the root link to the world (no free joint), as a `world` link and a fixed "
    "joint do; the robot's own joints still move.",
)
COACD_CPU_LIMIT = Opt(
    ("--coacd-cpu-limit", "--coacd-time-limit"),
    "coacd_cpu_limit",
    "CPU seconds CoACD may spend decomposing one collision mesh before its convex hull stands "
    "in (default 60; the same on an idle and a busy machine). --coacd-time-limit: older name.",
    float,
    envvar="TWIN_COACD_CPU_LIMIT",  # converters.collision.plan.CPU_LIMIT_ENV
)
NAME = Arg("name", "Entity name (see `twin list`).", str)
