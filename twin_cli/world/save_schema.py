"""The save file's schema: what `twin load` accepts, checked before any of it reaches a world.

A save file is input like any other: it may be truncated, edited or hostile. Every field is
checked for its type, every number for being finite (limits may be infinite, never NaN) and
within its physical range (`twin_cli.physical_ranges`), and counters for their range, so a bad
file gets one message with the path of the bad field and the world it would replace stays as
it was.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError

from twin_cli.names import name_message, name_problem
from twin_cli.physical_ranges import (
    MAX_VALUE,
    Acceleration,
    Angle,
    CommandValue,
    Force,
    Gain,
    Iterations,
    Position,
    Rate,
    Timestep,
)

Finite = Annotated[float, Field(allow_inf_nan=False)]
Count = Annotated[int, Field(ge=0, le=2**53)]  # exactly representable in a JSON double


def _not_nan(value: float) -> float:
    if math.isnan(value):
        raise ValueError("NaN is not a number a world can hold")
    return value


def _finite_array(value: Any) -> Any:
    """Nested lists of finite numbers (a state array as `tolist()` wrote it)."""
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ValueError("not an array of numbers") from exc
    if not np.all(np.isfinite(array)):
        raise ValueError("holds NaN or infinity")
    if array.size and float(np.max(np.abs(array))) > MAX_VALUE:
        raise ValueError(f"holds a value beyond ±{MAX_VALUE:g}, which MuJoCo treats as bad")
    return value


def _state_fields(state: dict[str, Any]) -> dict[str, Any]:
    from twin_cli.world.entities import EntityState

    expected = set(EntityState.__dataclass_fields__)
    if set(state) != expected:
        raise ValueError(f"the arrays are {sorted(state)}, a spawn state has {sorted(expected)}")
    return state


def _entity_name(name: str) -> str:
    if name_problem(name) is not None:
        raise ValueError(name_message(name))
    return name


Limit = Annotated[float, AfterValidator(_not_nan)]  # an effort or speed limit: may be infinite
FiniteArray = Annotated[list, AfterValidator(_finite_array)]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class SavedPose(Strict):
    x: Position
    y: Position
    z: Position
    roll: Angle
    pitch: Angle
    yaw: Angle


class SavedEntity(Strict):
    name: Annotated[str, AfterValidator(_entity_name)]
    source: str
    pose: SavedPose
    xml: str | None
    args: dict[str, str] = {}
    package_paths: dict[str, str] = {}
    env: dict[str, str] | None = None
    joints: dict[str, Position] = {}
    on_ground: bool = False
    repair_inertia: bool = False
    strict: bool = False
    drop_dangling: bool = False  # written by older saves; dropping is the default now, not read
    fixed_base: bool = False
    coacd_cpu_limit: Annotated[float, Field(gt=0.0)] | None = None  # [CPU s]
    spawn_state: Annotated[dict[str, FiniteArray], AfterValidator(_state_fields)]


OBSOLETE_COMMAND_FIELDS = {"hold", "hold_slope"}
"""Command fields of saves written when fixed-base position servos fed the posture's gravity
load forward themselves (now MuJoCo's gravity compensation): read, then left out."""


class SavedCommand(Strict):
    actuator: str
    mode: Literal["position", "velocity", "effort"]
    target: CommandValue
    kp: Gain
    kv: Gain
    effort: Limit
    velocity_limit: Limit = math.inf
    feedforward: Force = 0.0
    rule: str = ""
    native: bool = False
    hold: Finite = 0.0  # OBSOLETE_COMMAND_FIELDS
    hold_slope: Finite = 0.0


class SavedPush(Strict):
    body: str
    wrench: Annotated[list[Force], Field(min_length=6, max_length=6)]
    end_step: Count


class SavedSettings(Strict):
    timestep: Timestep
    rate: Rate
    gravity: Annotated[list[Acceleration], Field(min_length=3, max_length=3)]
    iterations: Iterations
    ground: bool
    solver: str
    integrator: str
    contact_max_correcting_vel: Finite = 100.0


class SaveDocument(Strict):
    format: Literal["twin-world"]
    version: Literal[1]
    name: str
    settings: SavedSettings
    paused: bool
    iterations: Count
    divergences: Count
    entities: list[SavedEntity]
    commands: list[SavedCommand]
    pushes: list[SavedPush]
    layout: dict[str, Count]
    state: FiniteArray


def checked_document(data: Any) -> tuple[SaveDocument | None, str]:
    """The validated document, or None and one line naming the first bad field."""
    try:
        return SaveDocument.model_validate(data), ""
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "the document"
        detail = first["msg"].removeprefix("Value error, ")
        more = f" (and {exc.error_count() - 1} more)" if exc.error_count() > 1 else ""
        return None, f"{where}: {detail}{more}"
