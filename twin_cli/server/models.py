"""pydantic bodies of the world server's requests: untrusted input, validated at the door.

Every body rejects unknown fields (a typo is an error, not a silent no-op) and non-finite
numbers (JSON `NaN` parses in Python). Units are SI: m, rad, s, N, N m, Hz.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

Finite = Annotated[float, Field(allow_inf_nan=False)]
Vector = tuple[Finite, Finite, Finite]
EntityName = Annotated[str, Field(min_length=1, max_length=200, pattern=r"^[^/\s][^/]*$")]


class Body(BaseModel):
    """Request bodies reject unknown fields, so a typo is an error rather than a no-op."""

    model_config = ConfigDict(extra="forbid")


class PoseBody(Body):
    """A pose: position [m] and extrinsic roll-pitch-yaw [rad], as Gazebo's -x..-Y."""

    x: Finite = 0.0
    y: Finite = 0.0
    z: Finite = 0.0
    roll: Finite = 0.0
    pitch: Finite = 0.0
    yaw: Finite = 0.0


class SpawnBody(Body):
    """Spawn a file (absolute path on the server host) at a pose, with xacro args and packages."""

    source: Annotated[str, Field(min_length=1, description="absolute path on the server host")]
    name: EntityName | None = None
    pose: PoseBody = PoseBody()
    args: dict[str, str] = {}
    package_paths: dict[str, str] = {}
    on_ground: bool = False
    joints: dict[str, Finite] = Field(
        default={}, description="initial joint positions [rad] or [m] by URDF joint name (-J)"
    )


class PushBody(Body):
    """A world-frame force [N] and torque [N m] on a link for `duration` seconds of sim time."""

    force: Vector = (0.0, 0.0, 0.0)
    torque: Vector = (0.0, 0.0, 0.0)
    link: str | None = None
    duration: Annotated[float, Field(gt=0.0, le=3600.0, description="[s] of sim time")] = 0.1


class CommandBody(Body):
    """A joint command: position [rad or m], velocity [rad/s or m/s] or effort [N m or N]."""

    joint: str
    mode: Literal["position", "velocity", "effort"]
    value: Finite


class GravityBody(Body):
    """Gravity from a named preset or an explicit vector [m/s^2], exactly one of them."""

    preset: Literal["earth", "moon", "mars", "zero"] | None = None
    vector: Vector | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> GravityBody:
        if (self.preset is None) == (self.vector is None):
            raise ValueError("give exactly one of 'preset' or 'vector'")
        return self


class PhysicsBody(Body):
    """Physics settings to change; fields left out keep their value."""

    timestep: Annotated[float, Field(gt=0.0, le=0.1, description="[s]")] | None = None
    rate: Annotated[float, Field(ge=0.0, le=1e7, description="[Hz]; 0 = unthrottled")] | None = None
    iterations: Annotated[int, Field(ge=1, le=100_000)] | None = None
    solver: str | None = None
    integrator: str | None = None


class StepBody(Body):
    """Advance `n` physics steps (allowed while paused)."""

    n: Annotated[int, Field(ge=1, le=10_000_000)] = 1


class ResetBody(Body):
    """Reset entities and time, or only time."""

    time_only: bool = False


class PathBody(Body):
    """A file on the server host (absolute, or relative to the server's working directory)."""

    path: Annotated[str, Field(min_length=1)]
