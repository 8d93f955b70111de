"""Every world command declared once: its help, arguments, options and the action it calls.

Plain Python (stdlib only), so the fast path (`fast.py`) reads it without importing Typer, and
`commands/world.py` builds the Typer commands (help, usage errors) from the same entries.
Parameters are listed in `--help` order; `dest` is the keyword the `world_actions` function takes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Opt:
    """An option: its flags, the keyword it fills, how a value converts (None: a bool flag)."""

    flags: tuple[str, ...]
    dest: str
    help: str
    convert: type | None = None
    default: Any = None
    nargs: int = 1
    multiple: bool = False
    envvar: str | None = None  # read when the option is not given (Typer's `envvar=`)


@dataclass(frozen=True)
class Arg:
    """A positional argument; `minimum` bounds an int (Typer's `min=`)."""

    dest: str
    help: str
    convert: type
    required: bool = True
    default: Any = None
    minimum: int | None = None


@dataclass(frozen=True)
class Command:
    """One world command: the `world_actions` function it calls, its help and parameters."""

    action: str
    help: str
    params: tuple[Arg | Opt, ...] = ()

    @property
    def args(self) -> tuple[Arg, ...]:
        return tuple(p for p in self.params if isinstance(p, Arg))

    @property
    def opts(self) -> tuple[Opt, ...]:
        return tuple(p for p in self.params if isinstance(p, Opt))


def flag(*flags: str, dest: str, help: str) -> Opt:
    """A bool option, off unless given."""
    return Opt(flags, dest, help, None, False)


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
POSE = tuple(
    Opt((short,), dest, f"Spawn {what}.", float, 0.0)
    for short, dest, what in (
        ("-x", "x", "x [m]"),
        ("-y", "y", "y [m]"),
        ("-z", "z", "z [m]"),
        ("-R", "roll", "roll [rad]"),
        ("-P", "pitch", "pitch [rad]"),
        ("-Y", "yaw", "yaw [rad]"),
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

SPAWN = Command(
    "spawn",
    "Spawn a robot or model; prints its name once it exists in the world.\n\n"
    "Packages (`$(find)`, `package://`, `model://`) resolve with this shell's ROS_PACKAGE_PATH,\n"
    "AMENT_PREFIX_PATH, GAZEBO_MODEL_PATH and GZ_SIM_RESOURCE_PATH, as `twin convert` would.",
    (
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
    ),
)

PUSH = Command(
    "push",
    "Apply a force and torque to an entity for a while.",
    (
        NAME,
        Opt(("--force",), "force", "Force FX FY FZ (N), world frame.", float, (0, 0, 0), 3),
        Opt(("--torque",), "torque", "Torque TX TY TZ (N m).", float, (0, 0, 0), 3),
        Opt(("--link",), "link", "Link to push (default: the root).", str),
        Opt(("--duration",), "duration", "How long (s) of sim time.", float, 0.1),
        WORLD,
        JSON,
    ),
)

GRAVITY = Command(
    "gravity",
    "Print the gravity vector, or set it from a preset or --set X Y Z.",
    (
        flag("--earth", dest="earth", help="(0, 0, -9.81)"),
        flag("--moon", dest="moon", help="(0, 0, -1.62)"),
        flag("--mars", dest="mars", help="(0, 0, -3.71)"),
        flag("--zero", dest="zero", help="(0, 0, 0)"),
        Opt(("--set",), "set_", "X Y Z (m/s^2).", float, nargs=3),
        WORLD,
        JSON,
    ),
)

PHYSICS = Command(
    "physics",
    "Print the physics settings, or change step, rate, iterations, threads or sleeping.",
    (
        Opt(("--step",), "step", "Physics step (s).", float),
        Opt(("--rate",), "rate", "Real-time update rate (Hz); 0 = max.", float),
        Opt(("--iterations",), "iterations", "Solver iterations.", int),
        WORLD,
        JSON,
        Opt(("--threads",), "threads", "MuJoCo engine threads, 1-64 (default 1: no pool).", int),
        flag("--sleep", dest="sleep", help="Let resting robots sleep (off by default)."),
        flag("--no-sleep", dest="no_sleep", help="Keep every robot awake."),
        Opt(
            ("--sleep-tolerance",),
            "sleep_tolerance",
            "Speed (m/s) under which a robot may sleep.",
            float,
        ),
    ),
)

STATS = Command(
    "stats",
    "Print `Factor[..] SimTime[..] RealTime[..] Paused[..]` about five times a second, until "
    "--duration ends or Ctrl-C.",
    (
        Opt(("-d", "--duration"), "duration", "Seconds to run (default: forever).", float),
        flag("-p", "--plot", dest="plot", help="Comma-separated values."),
        WORLD,
        flag(
            "--json",
            dest="json",
            help="Print one JSON object a line, about five a second, streamed until --duration "
            "ends or Ctrl-C (without -d it never ends).",
        ),
    ),
)

# `twin NAME` → its declaration, in the order of `twin --help`.
COMMANDS: dict[str, Command] = {
    "stop": Command(
        "stop", "Stop the world's server (waits until its process has ended).", (WORLD,)
    ),
    "spawn": SPAWN,
    "delete": Command("delete", "Delete an entity.", (NAME, WORLD)),
    "list": Command("list_", "List the entities in the world.", (WORLD, JSON)),
    "pose": Command(
        "pose",
        "Print an entity's pose as `x y z roll pitch yaw` (or move it with --set).",
        (
            NAME,
            Opt(("--set",), "set_", "Move it: X Y Z (m) ROLL PITCH YAW (rad).", float, nargs=6),
            WORLD,
            JSON,
            flag("--quat", dest="quat", help="Print x y z qx qy qz qw (a quaternion)."),
        ),
    ),
    "joints": Command(
        "joints", "Print an entity's joint positions, velocities and efforts.", (NAME, WORLD, JSON)
    ),
    "push": PUSH,
    "gravity": GRAVITY,
    "physics": PHYSICS,
    "pause": Command("pause", "Pause the simulation.", (WORLD,)),
    "resume": Command("resume", "Resume the simulation.", (WORLD,)),
    "step": Command(
        "step",
        "Advance the simulation N steps (also while paused).",
        (Arg("n", "Number of steps.", int, False, 1, minimum=1), WORLD, JSON),
    ),
    "reset": Command(
        "reset",
        "Reset the world (entities to their spawn poses, time to 0), or only its time.",
        (flag("--time-only", dest="time_only", help="Only reset time."), WORLD),
    ),
    "stats": STATS,
    "save": Command(
        "save",
        "Save the world (entities, state, physics) to a file `twin load` reads.",
        (
            Arg("file", "Where to write the world.", Path),
            WORLD,
            flag("--force", dest="force", help="Replace FILE even if twin did not write it."),
        ),
    ),
    "load": Command(
        "load",
        "Replace the running world by one saved with `twin save` (starts the world if none runs).",
        (
            Arg("file", "A file written by `twin save`.", Path, False),
            WORLD,
            flag("--last", dest="last", help="The world's last autosave (after a crash)."),
        ),
    ),
    "logs": Command(
        "logs",
        "Print the world server's log file.",
        (Opt(("-n", "--lines"), "lines", "Only the last N.", int), WORLD),
    ),
}
