"""Repeated `NAME<sep>VALUE` options (--arg, --package, -J) parsed without Typer.

Shared by the Typer app (`options`, which turns BadOption into Typer's usage error) and the fast
path (`fast`, which hands a bad value to the Typer app so that it prints the usage message).
"""

from __future__ import annotations

import math


class BadOption(ValueError):
    """An option value that does not parse; the message names the option and the fix."""


def parse_pairs(items: list[str] | None, sep: str, what: str) -> dict[str, str]:
    """Parse repeated `NAME<sep>VALUE` options into a dict.

    Raises:
        BadOption: an item without `sep`.
    """
    out: dict[str, str] = {}
    for item in items or []:
        if sep not in item:
            raise BadOption(f"{what} {item!r} must look like NAME{sep}VALUE")
        name, value = item.split(sep, 1)
        out[name.strip()] = value.strip()
    return out


def joint_positions(items: list[str] | None) -> dict[str, float]:
    """Repeated `-J NAME=POS` as joint name → position [rad] or [m].

    Gazebo's `spawn_model -J NAME POS` takes two values per flag; Typer cannot repeat an option
    of two values ("List types with complex sub-types are not currently supported"), so twin
    takes one `NAME=POS` value per flag.

    Raises:
        BadOption: an item without `=` or whose position is not a number.
    """
    out: dict[str, float] = {}
    for name, value in parse_pairs(items, "=", "-J").items():
        if not name:
            raise BadOption(f"-J ={value}: the joint name is missing; give e.g. -J elbow=0.5")
        try:
            out[name] = float(value)
        except ValueError:
            raise BadOption(
                f"-J {name}={value}: {value!r} is not a number; give e.g. -J {name}=0.5"
            ) from None
        if not math.isfinite(out[name]):  # nan, inf and 1e309 parse as floats (fuzz found it)
            raise BadOption(
                f"-J {name}={value}: {value!r} is not a finite number; give e.g. -J {name}=0.5"
            )
    return out


def source_inputs(arg: list[str] | None, package: list[str] | None) -> dict[str, dict[str, str]]:
    """`--arg NAME:=VALUE` and `--package NAME=PATH` as the `args` and `package_paths` keywords
    that `convert`, `convert_full`, `validate` and `spawn` all take.

    Raises:
        BadOption: an item without its separator.
    """
    return {
        "args": parse_pairs(arg, ":=", "--arg"),
        "package_paths": parse_pairs(package, "=", "--package"),
    }
