"""Options shared by several commands, defined once (Gazebo's names where Gazebo has them)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import Annotated

import typer

from twin_cli.cli import pairs

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
    """`pairs.parse_pairs`, with a bad item reported as Typer's usage error (exit code 2)."""
    with usage_errors():
        return pairs.parse_pairs(items, sep, what)


def joint_positions(items: list[str] | None) -> dict[str, float]:
    """`pairs.joint_positions` (`-J NAME=POS`), a bad item reported as a usage error."""
    with usage_errors():
        return pairs.joint_positions(items)


def source_inputs(arg: list[str] | None, package: list[str] | None) -> dict[str, dict[str, str]]:
    """`pairs.source_inputs` (`--arg`, `--package`), a bad item reported as a usage error."""
    with usage_errors():
        return pairs.source_inputs(arg, package)


@contextmanager
def usage_errors() -> Iterator[None]:
    """Turns BadOption into typer.BadParameter: usage, the message, exit code 2."""
    try:
        yield
    except pairs.BadOption as exc:
        raise typer.BadParameter(str(exc)) from None
