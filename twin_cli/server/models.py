"""pydantic bodies of the world server's requests: untrusted input, validated at the door.

Every body rejects unknown fields (a typo is an error, not a silent no-op) and non-finite
numbers (JSON `NaN` parses in Python). Units are SI: m, rad, s, N, N m, Hz.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from twin_cli.names import name_message, name_problem
from twin_cli.physical_ranges import (
    Acceleration,
    Angle,
    CommandValue,
    Force,
    Iterations,
    Position,
    Rate,
    Timestep,
)
from twin_cli.server.body_limit import MAX_BODY_BYTES
from twin_cli.spawn_request import SpawnRequest

Finite = Annotated[float, Field(allow_inf_nan=False)]


def _entity_name(name: str) -> str:
    """The one name rule (twin_cli.names), with its message instead of a regex's."""
    if name_problem(name) is not None:
        raise ValueError(name_message(name))
    return name


EntityName = Annotated[
    str,
    AfterValidator(_entity_name),
    Field(min_length=1, max_length=200, description="1-200 characters without '/' or spaces"),
]


def _absolute(path: str) -> str:
    """A path the client resolved: the server's working folder is not the user's, so a relative
    path (`../../etc/passwd`) would land wherever the server happened to start."""
    if "\x00" in path:
        raise ValueError("a path cannot hold a NUL character")
    if not path.startswith("/"):
        raise ValueError(f"{path!r} is relative: send an absolute path (the twin CLI does)")
    return path


HostPath = Annotated[
    str,
    AfterValidator(_absolute),
    Field(min_length=1, max_length=4096, description="absolute path on the server host"),
]


class Body(BaseModel):
    """Request bodies reject unknown fields, so a typo is an error rather than a no-op."""

    model_config = ConfigDict(extra="forbid")


class PoseBody(Body):
    """A pose: position [m] and extrinsic roll-pitch-yaw [rad] (Gazebo's -x..-Y), or instead of
    roll-pitch-yaw a quaternion `quat` (x, y, z, w) as geometry_msgs/Pose and SpawnEntity give."""

    x: Position = 0.0
    y: Position = 0.0
    z: Position = 0.0
    roll: Angle = 0.0
    pitch: Angle = 0.0
    yaw: Angle = 0.0
    quat: tuple[Position, Position, Position, Position] | None = Field(
        default=None, description="orientation (x, y, z, w); replaces roll, pitch, yaw"
    )

    @model_validator(mode="after")
    def _one_orientation(self) -> PoseBody:
        if self.quat is None:
            return self
        if any((self.roll, self.pitch, self.yaw)):
            raise ValueError("give either 'quat' or 'roll'/'pitch'/'yaw', not both")
        if sum(v * v for v in self.quat) < 1e-12:
            raise ValueError("'quat' must not be zero; a unit quaternion (x, y, z, w) is expected")
        return self


class SpawnBody(Body):
    """Spawn a description at a pose: a file on the server host (`source`), or its text (`xml`:
    URDF, xacro output, SDF or MJCF, as SpawnEntity's `xml`), with xacro args and packages."""

    source: HostPath | None = None
    xml: Annotated[str, Field(min_length=1, max_length=MAX_BODY_BYTES)] | None = Field(
        default=None, description="the description as text, instead of `source`"
    )
    base_dir: HostPath | None = Field(
        default=None, description="where relative mesh paths in `xml` start (absolute)"
    )
    name: EntityName | None = None
    pose: PoseBody = PoseBody()
    args: dict[str, str] = {}
    package_paths: dict[str, HostPath] = {}
    on_ground: bool = False
    joints: dict[str, Position] = Field(
        default={}, description="initial joint positions [rad] or [m] by URDF joint name (-J)"
    )
    env: dict[str, str] | None = Field(
        default=None,
        description="package search variables (ROS_PACKAGE_PATH, AMENT_PREFIX_PATH, "
        "GAZEBO_MODEL_PATH, GZ_SIM_RESOURCE_PATH) to resolve with; absent: the server's own",
    )
    repair_inertia: bool = Field(
        default=False, description="bound non-physical inertias instead of refusing the file"
    )
    strict: bool = Field(
        default=False,
        description="refuse tags that name a missing link or joint, and visuals whose mesh is "
        "missing, instead of leaving them out with a warning (Gazebo's behaviour)",
    )
    drop_dangling: bool = Field(
        default=False,
        description="older clients' flag: leaving those out is the default now; not read",
    )
    fixed_base: bool = Field(
        default=False,
        description="weld the root link to the world at the spawn pose (no free joint)",
    )
    coacd_cpu_limit: float | None = Field(
        default=None,
        gt=0.0,
        le=86_400.0,
        description="CPU seconds CoACD may spend on one collision mesh before its convex hull "
        "stands in; absent: the server's default",
    )

    @model_validator(mode="after")
    def _one_source(self) -> SpawnBody:
        if (self.source is None) == (self.xml is None):
            raise ValueError("give exactly one of 'source' (a file path) or 'xml' (its text)")
        return self

    def request(self) -> SpawnRequest:
        """The spawn request this body carries (everything but the names and poses)."""
        return SpawnRequest.from_body(self.model_dump(exclude={"name", "pose", "poses", "names"}))


class PushBody(Body):
    """A world-frame force [N] and torque [N m] on a link for `duration` seconds of sim time."""

    force: tuple[Force, Force, Force] = (0.0, 0.0, 0.0)
    torque: tuple[Force, Force, Force] = (0.0, 0.0, 0.0)
    link: str | None = None
    duration: Annotated[float, Field(gt=0.0, le=3600.0, description="[s] of sim time")] = 0.1


class CommandBody(Body):
    """A joint command: position [rad or m], velocity [rad/s or m/s] or effort [N m or N]."""

    joint: str
    mode: Literal["position", "velocity", "effort"]
    value: CommandValue


class GravityBody(Body):
    """Gravity from a named preset or an explicit vector [m/s^2], exactly one of them."""

    preset: Literal["earth", "moon", "mars", "zero"] | None = None
    vector: tuple[Acceleration, Acceleration, Acceleration] | None = None

    @model_validator(mode="after")
    def _exactly_one(self) -> GravityBody:
        if (self.preset is None) == (self.vector is None):
            raise ValueError("give exactly one of 'preset' or 'vector'")
        return self


class PhysicsBody(Body):
    """Physics settings to change; fields left out keep their value."""

    timestep: Timestep | None = None
    rate: Rate | None = Field(default=None, description="[Hz]; 0 = unthrottled")
    iterations: Iterations | None = None
    solver: str | None = None
    integrator: str | None = None
    threads: Annotated[int, Field(ge=1, le=64, description="engine threads")] | None = None
    sleep: bool | None = Field(default=None, description="sleeping of resting islands")
    sleep_tolerance: Annotated[float, Field(gt=0.0, lt=10.0, description="[m/s]")] | None = None


class StepBody(Body):
    """Advance `n` physics steps (allowed while paused)."""

    n: Annotated[int, Field(ge=1, le=10_000_000)] = 1


class ResetBody(Body):
    """Reset entities and time, or only time."""

    time_only: bool = False


class PathBody(Body):
    """A file on the server host, by its absolute path."""

    path: HostPath


class SaveBody(PathBody):
    """`twin save`: the file; an existing file that is not a twin save needs `force`."""

    force: bool = False


class RecordBody(Body):
    """`twin record`: a rosbag2 MCAP file on the server host, sampled in sim time."""

    path: HostPath
    rate: Annotated[Finite, Field(gt=0, le=1000)] = 100.0
    entities: list[EntityName] = []
    duration: Annotated[Finite, Field(gt=0)] | None = None


class FoxgloveBody(Body):
    """`twin foxglove`: a live Foxglove WebSocket server (loopback unless a host is given)."""

    port: Annotated[int, Field(ge=0, le=65535)] = 8765
    host: str = "127.0.0.1"
    rate: Annotated[Finite, Field(gt=0, le=1000)] = 30.0


class RosBody(Body):
    """`twin ros start`: join the ROS 2 graph; loopback only unless an interface is given."""

    interface: Annotated[str, Field(min_length=1, max_length=64)] | None = None
    # the client's ROS_DOMAIN_ID and discovery variables (None: the server's own)
    environment: dict[Annotated[str, Field(pattern=r"^ROS_[A-Z_]+$")], str] | None = None
    # gazebo_ros' /spawn_entity and /delete_entity: any DDS peer in the scope may call them
    services: bool = False


class SpawnBatchBody(SpawnBody):
    """Spawn one description at many poses in one request and one recompile (all or nothing):
    entities `names`, else `name_0`, `name_1`, … (`name` defaults to the robot's own name)."""

    poses: Annotated[list[PoseBody], Field(min_length=1, max_length=1000)]
    names: list[EntityName] | None = None


class ViewBody(Body):
    """`twin view`: MuJoCo's web viewer on this world (loopback unless a host is given)."""

    port: Annotated[int, Field(ge=0, le=65535)] = 0
    host: str = "127.0.0.1"
    quality: Literal["auto", "full", "fast"] | None = None  # None: auto, or the running one's


class SnapshotBody(Body):
    """`twin snapshot`: a PNG of the world rendered offscreen, written on the server's host."""

    path: HostPath
    force: bool = False  # replace an existing file that is not a PNG twin wrote
    entity: str | None = None
    width: Annotated[int, Field(ge=1, le=4096)] = 640
    height: Annotated[int, Field(ge=1, le=4096)] = 480
