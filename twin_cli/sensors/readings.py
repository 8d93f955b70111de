"""What a sensor reports, one frozen record per message kind (sensor_msgs equivalents).

Every reading carries the sensor's name, Gazebo type, the sim time [s] it was taken at and its
ROS frame. `to_dict` gives JSON-ready values: tuples become lists and an infinite range (no
return within `range_max`, LaserScan's +inf) becomes null, since JSON has no infinity.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any


def jsonable(value: Any) -> Any:
    """Tuples → lists, nested records → dicts, ±inf/nan → None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, (tuple, list)):
        return [jsonable(v) for v in value]
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    return value


@dataclass(frozen=True)
class Reading:
    """Common header: sensor name, Gazebo type, sim time [s], frame id."""

    sensor: str
    type: str
    time: float
    frame_id: str

    def to_dict(self) -> dict[str, Any]:
        return jsonable(self)


Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class ImuReading(Reading):
    """sensor_msgs/Imu: orientation (x, y, z, w) of the sensor in the world, angular velocity
    [rad/s] and specific force (acceleration minus gravity) [m/s²], both in the sensor frame."""

    orientation: tuple[float, float, float, float]
    angular_velocity: Vec3
    linear_acceleration: Vec3


@dataclass(frozen=True)
class ScanReading(Reading):
    """sensor_msgs/LaserScan: `ranges` [m], +inf where nothing is within `range_max`.

    With more than one vertical ray the ranges are row after row (`vertical_count` rows,
    lowest angle first), each row `len(ranges) // vertical_count` long.
    """

    angle_min: float
    angle_max: float
    angle_increment: float
    scan_time: float
    range_min: float
    range_max: float
    ranges: tuple[float, ...]
    vertical_count: int = 1


@dataclass(frozen=True)
class ContactState:
    """One contact of the sensor's link: its geom, the other geom, the force on the link [N]
    (world frame), the contact point [m], the normal (from the other geom into the link) and
    the penetration depth [m]."""

    collision1: str
    collision2: str
    force: Vec3
    position: Vec3
    normal: Vec3
    depth: float


@dataclass(frozen=True)
class ContactReading(Reading):
    """gazebo_msgs/ContactsState: every contact on the link's collision geoms now."""

    states: tuple[ContactState, ...]
    total_force: Vec3

    @property
    def in_contact(self) -> bool:
        return bool(self.states)


@dataclass(frozen=True)
class WrenchReading(Reading):
    """geometry_msgs/WrenchStamped: force [N] and torque [N m] at the sensor's origin, in
    `frame` (`child`, `parent` or `sensor`), `measure_direction` as the SDF tag."""

    force: Vec3
    torque: Vec3
    frame: str
    measure_direction: str


@dataclass(frozen=True)
class ImageReading(Reading):
    """sensor_msgs/Image: `width`×`height`, `encoding` rgb8 or 32FC1 (depth [m]; −inf nearer
    than the clip's near plane, +inf from its far plane, as REP 117); `data` is the raw bytes
    (rows top to bottom), omitted from `to_dict` (served as its size only)."""

    width: int
    height: int
    encoding: str
    data: bytes = dataclasses.field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        out = {k: v for k, v in jsonable(dataclasses.replace(self, data=b"")).items()}
        out["data"] = None
        out["bytes"] = len(self.data)
        return out
