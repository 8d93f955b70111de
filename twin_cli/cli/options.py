"""Options shared by several commands, defined once (Gazebo's names where Gazebo has them)."""

from __future__ import annotations

from typing import Annotated

import typer

JsonOpt = Annotated[bool, typer.Option("--json", help="Print machine-readable JSON.")]
WorldOpt = Annotated[
    str,
    typer.Option("--world", envvar="TWIN_WORLD", help="Name of the world to talk to."),
]
ArgOpt = Annotated[
    list[str] | None,
    typer.Option("--arg", help="xacro argument NAME:=VALUE (repeatable)."),
]
PackageOpt = Annotated[
    list[str] | None,
    typer.Option("--package", help="Package location NAME=PATH (repeatable)."),
]
JointOpt = Annotated[
    list[str] | None,
    typer.Option(
        "-J",
        "--joint",
        help="Initial joint position NAME=POS [rad or m] (repeatable; Gazebo's -J NAME POS).",
    ),
]
XOpt = Annotated[float, typer.Option("-x", help="Spawn x [m].")]
YOpt = Annotated[float, typer.Option("-y", help="Spawn y [m].")]
ZOpt = Annotated[float, typer.Option("-z", help="Spawn z [m].")]
RollOpt = Annotated[float, typer.Option("-R", help="Spawn roll [rad].")]
PitchOpt = Annotated[float, typer.Option("-P", help="Spawn pitch [rad].")]
YawOpt = Annotated[float, typer.Option("-Y", help="Spawn yaw [rad].")]


def parse_pairs(items: list[str] | None, sep: str, what: str) -> dict[str, str]:
    """Parse repeated `NAME<sep>VALUE` options into a dict, with a clear error for bad items."""
    out: dict[str, str] = {}
    for item in items or []:
        if sep not in item:
            raise typer.BadParameter(f"{what} {item!r} must look like NAME{sep}VALUE")
        name, value = item.split(sep, 1)
        out[name.strip()] = value.strip()
    return out


def joint_positions(items: list[str] | None) -> dict[str, float]:
    """Repeated `-J NAME=POS` as joint name → position [rad] or [m].

    Gazebo's `spawn_model -J NAME POS` takes two values per flag; Typer cannot repeat an option
    of two values ("List types with complex sub-types are not currently supported"), so twin
    takes one `NAME=POS` value per flag.
    """
    out: dict[str, float] = {}
    for name, value in parse_pairs(items, "=", "-J").items():
        try:
            out[name] = float(value)
        except ValueError:
            raise typer.BadParameter(
                f"-J {name}={value}: {value!r} is not a number; give e.g. -J {name}=0.5"
            ) from None
    return out


def source_inputs(arg: list[str] | None, package: list[str] | None) -> dict[str, dict[str, str]]:
    """`--arg NAME:=VALUE` and `--package NAME=PATH` as the `args` and `package_paths` keywords
    that `convert`, `convert_full`, `validate` and `spawn` all take."""
    return {
        "args": parse_pairs(arg, ":=", "--arg"),
        "package_paths": parse_pairs(package, "=", "--package"),
    }
