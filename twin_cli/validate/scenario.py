"""Scenario files (TOML) → validated, typed scenarios that `twin validate` runs.

A scenario says which world to build (gravity, ground, incline, obstacles), where the robot
starts, what is done to it (pushes, joint drives, torques, a posture hold), for how long, and
which check judges it with which thresholds. Untrusted input, so pydantic with `extra="forbid"`:
every mistake becomes a `ScenarioError` naming the file, the key and the fix.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from scenarios import SCENARIO_DIR
from twin_cli.errors import ScenarioError

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10: the same parser under its PyPI name
    import tomli as tomllib

# Same presets as the world engine (twin_cli.world.engine.GRAVITY_PRESETS) [m/s²]; kept here so that
# parsing a scenario never imports mujoco.
GRAVITY_PRESETS: dict[str, tuple[float, float, float]] = {
    "earth": (0.0, 0.0, -9.81),
    "moon": (0.0, 0.0, -1.62),
    "mars": (0.0, 0.0, -3.71),
    "zero": (0.0, 0.0, 0.0),
}

Vec3 = tuple[float, float, float]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class PoseSpec(_Strict):
    """A pose [m], [rad] (roll, pitch, yaw as Gazebo)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0


class Obstacle(_Strict):
    """A static box. `ahead_gap` [m] places its near face that far in front (+x) of the robot."""

    shape: Literal["box"] = "box"
    size: Vec3 = (0.2, 1.0, 1.0)
    pose: PoseSpec = PoseSpec()
    ahead_gap: float | None = None
    mu: float = 1.0

    @field_validator("size")
    @classmethod
    def _positive(cls, value: Vec3) -> Vec3:
        if min(value) <= 0:
            raise ValueError("every box size must be > 0 m")
        return value


class WorldSpec(_Strict):
    """The scenario's world; `incline_deg` tilts gravity about +y (a slope rising towards +x)."""

    gravity: str | Vec3 = "earth"
    ground: bool = True
    incline_deg: float = Field(default=0.0, ge=0.0, lt=90.0)
    timestep: float = Field(default=0.001, gt=0.0, le=0.05)
    rate: float = Field(default=1000.0, ge=0.0)

    @field_validator("gravity")
    @classmethod
    def _known_preset(cls, value: str | Vec3) -> str | Vec3:
        if isinstance(value, str) and value not in GRAVITY_PRESETS:
            raise ValueError(f"unknown preset {value!r}; use one of {', '.join(GRAVITY_PRESETS)}")
        return value

    def gravity_vector(self) -> Vec3:
        """Gravity [m/s²] in the world frame, tilted by the incline."""
        g = GRAVITY_PRESETS[self.gravity] if isinstance(self.gravity, str) else self.gravity
        theta = math.radians(self.incline_deg)
        # Rotating the slope by +θ about y equals rotating gravity by −θ about y.
        x = g[0] * math.cos(theta) + g[2] * math.sin(theta)
        z = -g[0] * math.sin(theta) + g[2] * math.cos(theta)
        return (x, g[1], z)


class RobotStart(_Strict):
    """Where the robot starts; `on_ground` lowers it until its lowest geom touches z = 0.

    `joints`: start positions [rad] or [m] by URDF joint name (Gazebo's `-J`), the rest from the
    robot's home configuration; a `[hold]` holds this posture.
    """

    pose: PoseSpec = PoseSpec()
    on_ground: bool = False
    joints: dict[str, float] = {}

    @field_validator("joints")
    @classmethod
    def _finite(cls, value: dict[str, float]) -> dict[str, float]:
        for name, position in value.items():
            if not math.isfinite(position):
                raise ValueError(f"joint {name!r}: position {position} is not finite")
        return value


class Hold(_Strict):
    """Hold the start posture with joint PD (like ros_control position controllers).

    Gains [N m/rad], [N m s/rad] (or N/m, N s/m for prismatic joints); torque clipped to each
    joint's effort limit.
    """

    kp: float = Field(default=300.0, ge=0.0)
    kd: float = Field(default=10.0, ge=0.0)


class Action(_Strict):
    """Something done to the robot from `at` [s] for `duration` [s].

    push: `force` [N] or `force_per_kg` [N/kg] (scaled by the robot's mass), optional `torque`
    [N m], on `link` (root when omitted). drive: joints (`"*"` for all) at `effort` =
    "max"/"min" or a value [N m]. torque: `torque` [N m] on `link`.
    """

    kind: Literal["push", "drive", "torque"]
    at: float = Field(default=0.0, ge=0.0)
    duration: float = Field(default=0.1, gt=0.0)
    force: Vec3 | None = None
    force_per_kg: Vec3 | None = None
    torque: Vec3 | None = None
    link: str | None = None
    joints: list[str] | Literal["*"] = "*"
    effort: float | Literal["max", "min"] = "max"


class Scenario(_Strict):
    """One scenario file: a world, a start, actions, a duration, a check and its thresholds."""

    name: str
    check: str
    description: str = ""
    duration: float = Field(default=1.0, gt=0.0, le=60.0)
    world: WorldSpec = WorldSpec()
    robot: RobotStart = RobotStart()
    hold: Hold | None = None
    actions: list[Action] = []
    obstacles: list[Obstacle] = []
    thresholds: dict[str, float] = {}
    source: str = ""


def builtin_names() -> list[str]:
    """Names of the bundled scenarios (the built-in checklist), sorted."""
    return sorted(p.stem for p in SCENARIO_DIR.glob("*.toml"))


def load_builtin() -> list[Scenario]:
    """Every bundled scenario, in name order."""
    return [load_scenario(SCENARIO_DIR / f"{name}.toml") for name in builtin_names()]


def resolve(name_or_file: str) -> Scenario:
    """A bundled scenario by name, or a scenario file by path.

    Raises:
        ScenarioError: neither a bundled name nor an existing file.
    """
    path = Path(name_or_file)
    if path.suffix == ".toml" or path.exists():
        return load_scenario(path)
    if name_or_file in builtin_names():
        return load_scenario(SCENARIO_DIR / f"{name_or_file}.toml")
    raise ScenarioError(
        name_or_file,
        "",
        "no such scenario file or bundled scenario",
        f"give a .toml path or one of: {', '.join(builtin_names())}",
    )


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate one scenario file.

    Raises:
        ScenarioError: unreadable file, bad TOML, or a key with a wrong value or name.
    """
    path = Path(path)
    try:
        raw = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise ScenarioError(path, "", f"cannot read ({exc.strerror})", "check the path") from exc
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(path, "", f"not valid TOML ({exc})", "fix the syntax") from exc
    raw.setdefault("name", path.stem)
    raw["source"] = str(path)
    try:
        return Scenario.model_validate(raw)
    except ValidationError as exc:
        first = exc.errors()[0]
        key = ".".join(str(p) for p in first["loc"]) or "(top level)"
        raise ScenarioError(path, key, first["msg"], _fix_for(first)) from exc


def _fix_for(error: dict) -> str:
    """A fix sentence for one pydantic error."""
    if error["type"] == "extra_forbidden":
        return "remove it or check its spelling against docs/scenarios.md"
    if error["type"] == "missing":
        return "add this key (see docs/scenarios.md)"
    return "give a value of the documented type and range (see docs/scenarios.md)"


def with_joints(scenario: Scenario, joints: dict[str, float]) -> Scenario:
    """`scenario` with `joints` [rad] or [m] over its `[robot] joints` (the command line wins)."""
    if not joints:
        return scenario
    start = scenario.robot.model_copy(update={"joints": {**scenario.robot.joints, **joints}})
    return scenario.model_copy(update={"robot": start})
