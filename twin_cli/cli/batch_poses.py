"""`--at X,Y[,Z[,YAW]]` and `--names a,b,c` of `twin spawn`, parsed without Typer.

Shared by the Typer command and the fast path, like `pairs`; a bad value raises `BadOption`,
which both turn into a usage error naming the value (exit 2) before any request is sent, so a
bad pose among many spawns none.
"""

from __future__ import annotations

import math
from typing import Any

from twin_cli.cli.pairs import BadOption

AT_FORM = "X,Y[,Z[,YAW]] in metres and radians"


def parse_at(text: str, z: float, roll: float, pitch: float, yaw: float) -> dict[str, Any]:
    """One `--at` value as a request pose; missing Z and YAW come from -z and -Y.

    Raises:
        BadOption: not 2 to 4 comma-separated finite numbers.
    """
    parts = [p.strip() for p in text.split(",")]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        values = []
    if not 2 <= len(values) <= 4 or not all(math.isfinite(v) for v in values):
        raise BadOption(f"--at {text!r} is not a pose; give {AT_FORM}, e.g. --at 1,2")
    x, y = values[0], values[1]
    z = values[2] if len(values) > 2 else z
    yaw = values[3] if len(values) > 3 else yaw
    return {"x": x, "y": y, "z": z, "roll": roll, "pitch": pitch, "yaw": yaw}


def parse_names(text: str | None, count: int) -> list[str] | None:
    """`--names a,b,c`: one entity name per `--at`, or None when not given.

    Raises:
        BadOption: the count differs from the number of poses, or a name is empty or repeated.
    """
    if text is None:
        return None
    names = [n.strip() for n in text.split(",")]
    if len(names) != count or not all(names) or len(set(names)) != len(names):
        raise BadOption(
            f"--names {text!r} gives {len(names)} names for {count} poses; "
            "give one distinct name per --at, separated by commas"
        )
    from twin_cli.names import name_message, name_problem

    for name in names:
        if name_problem(name) is not None:
            raise BadOption(f"--names: {name_message(name)}")
    return names
