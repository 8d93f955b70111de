"""Sensor readings (`twin_cli.sensors`) as the ROS messages gazebo_ros sensor plugins publish.

IMU → sensor_msgs/Imu, ray → sensor_msgs/LaserScan (one row: the first vertical row), force/torque
→ geometry_msgs/WrenchStamped, contact/bumper → gazebo_msgs/ContactsState, camera and depth →
sensor_msgs/Image (rgb8, or 32FC1 metres as gazebo_ros' depth camera; little-endian rows).
The contact types are gazebo_msgs', which rosbags lacks (`contact_types` registers them).
Topics are `/<entity>/<topic>` with the sensor's `<topic>` (or its name); images go to
`/<entity>/<topic>/image_raw`, as gazebo_ros' cameras publish them.

Each kind's builder registers itself with `@ros_message(SpecType, ReadingType, ros_type)`: the
kinds below, and one module per further kind in `twin_cli.record.sensor_kinds` (imported the
first time a type is looked up), so a new kind's message is one module there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

import numpy as np

from converters.description.sensors import (
    CameraSpec,
    ContactSpec,
    ForceTorqueSpec,
    ImuSpec,
    RaySpec,
    SensorSpec,
)
from twin_cli.lazy import import_modules
from twin_cli.names import namespace
from twin_cli.record import messages as ros
from twin_cli.record.contact_types import CONTACTS
from twin_cli.record.topics import Message, Topic
from twin_cli.sensors import (
    ContactReading,
    ImageReading,
    ImuReading,
    Reading,
    ScanReading,
    WrenchReading,
)

IMU = "sensor_msgs/msg/Imu"
SCAN = "sensor_msgs/msg/LaserScan"
WRENCH = "geometry_msgs/msg/WrenchStamped"
IMAGE = "sensor_msgs/msg/Image"
KIND_PACKAGE = "twin_cli.record.sensor_kinds"  # its modules register further kinds' messages
PIXEL_BYTES = {"rgb8": 3, "32FC1": 4}
_UNKNOWN_COVARIANCE = np.zeros(9)  # sensor_msgs: all zeros = "covariance unknown"


Build = Callable[[Any, Any, Any], Any]  # (message classes, std_msgs Header, reading) → message
B = TypeVar("B", bound=Build)


@dataclass(frozen=True)
class SensorMessage:
    """One kind's message: its ROS type, its builder and the suffix of its topic."""

    ros_type: str
    build: Build
    suffix: str = ""


_BY_SPEC: dict[type, SensorMessage] = {}
_BY_READING: dict[type, SensorMessage] = {}
_BY_ROS_TYPE: dict[str, SensorMessage] = {}


def ros_message(
    spec_type: type, reading_type: type, ros_type: str, *, suffix: str = ""
) -> Callable[[B], B]:
    """Registers the decorated builder as the message of a sensor kind.

    Args:
        spec_type: the kind's record (`SensorSpec` subclass), so its topic is named before
            any reading; reading_type: its `Reading` subclass.
        ros_type: `pkg/msg/Type` of rosbags' typestore (`messages.typestore`).
        suffix: appended to the topic (`/image_raw` for images).

    The builder takes the message classes (`messages.types()`), the stamped header and the
    reading, and returns the message.
    """

    def register(build: B) -> B:
        entry = SensorMessage(ros_type, build, suffix)
        _BY_SPEC[spec_type] = _BY_READING[reading_type] = _BY_ROS_TYPE[ros_type] = entry
        return build

    return register


@cache
def _load_kinds() -> None:
    import_modules(KIND_PACKAGE)


def sensor_types() -> frozenset[str]:
    """The ROS types of every registered sensor message (offered with sensor QoS)."""
    _load_kinds()
    return frozenset(_BY_ROS_TYPE)


def sensor_topic(entity: str, name: str, topic: str, reading: Reading) -> Topic | None:
    """The topic of one sensor's readings (None: a kind that is not published)."""
    _load_kinds()
    return _named(entity, name, topic, _BY_READING.get(type(reading)))


def spec_topic(entity: str, spec: SensorSpec) -> Topic | None:
    """The topic a sensor's readings will go to, from its record (None: not published)."""
    _load_kinds()
    return _named(entity, spec.name, spec.topic, _BY_SPEC.get(type(spec)))


def _named(entity: str, name: str, topic: str, kind: SensorMessage | None) -> Topic | None:
    if kind is None:
        return None
    return Topic(f"{namespace(entity)}/{(topic or name).strip('/')}{kind.suffix}", kind.ros_type)


def sensor_message(topic: Topic, reading: Reading) -> Message:
    """The ROS message of `reading` on `topic`, stamped with its sim time."""
    _load_kinds()
    T = ros.types()
    header = T["std_msgs/msg/Header"](stamp=ros.stamp(reading.time), frame_id=reading.frame_id)
    build = _BY_ROS_TYPE[topic.type].build
    return Message(topic.name, topic.type, reading.time, build(T, header, reading))


def _vector(T: Any, v: Any) -> Any:
    return T["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))


@ros_message(ImuSpec, ImuReading, IMU)
def _imu(T: Any, header: Any, r: ImuReading) -> Any:
    x, y, z, w = (float(c) for c in r.orientation)
    return T[IMU](
        header=header,
        orientation=T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
        orientation_covariance=_UNKNOWN_COVARIANCE,
        angular_velocity=_vector(T, r.angular_velocity),
        angular_velocity_covariance=_UNKNOWN_COVARIANCE,
        linear_acceleration=_vector(T, r.linear_acceleration),
        linear_acceleration_covariance=_UNKNOWN_COVARIANCE,
    )


@ros_message(RaySpec, ScanReading, SCAN)
def _scan(T: Any, header: Any, r: ScanReading) -> Any:
    row = len(r.ranges) // max(1, r.vertical_count)
    return T[SCAN](
        header=header,
        angle_min=r.angle_min,
        angle_max=r.angle_max,
        angle_increment=r.angle_increment,
        time_increment=0.0,
        scan_time=r.scan_time,
        range_min=r.range_min,
        range_max=r.range_max,
        ranges=np.asarray(r.ranges[:row], dtype=np.float32),
        intensities=np.zeros(0, dtype=np.float32),
    )


@ros_message(ForceTorqueSpec, WrenchReading, WRENCH)
def _wrench(T: Any, header: Any, r: WrenchReading) -> Any:
    wrench = T["geometry_msgs/msg/Wrench"](force=_vector(T, r.force), torque=_vector(T, r.torque))
    return T[WRENCH](header=header, wrench=wrench)


@ros_message(ContactSpec, ContactReading, CONTACTS)
def _contacts(T: Any, header: Any, r: ContactReading) -> Any:
    zero = (0.0, 0.0, 0.0)
    states = []
    for c in r.states:
        wrench = T["geometry_msgs/msg/Wrench"](force=_vector(T, c.force), torque=_vector(T, zero))
        states.append(
            T["gazebo_msgs/msg/ContactState"](
                info=f"{c.collision1} touches {c.collision2}",
                collision1_name=c.collision1,
                collision2_name=c.collision2,
                wrenches=[wrench],
                total_wrench=wrench,
                contact_positions=[_vector(T, c.position)],
                contact_normals=[_vector(T, c.normal)],
                depths=np.array([c.depth]),
            )
        )
    return T[CONTACTS](header=header, states=states)


@ros_message(CameraSpec, ImageReading, IMAGE, suffix="/image_raw")  # as gazebo_ros' cameras
def _image(T: Any, header: Any, r: ImageReading) -> Any:
    return T[IMAGE](
        header=header,
        height=r.height,
        width=r.width,
        encoding=r.encoding,
        is_bigendian=0,
        step=r.width * PIXEL_BYTES[r.encoding],
        data=np.frombuffer(r.data, dtype=np.uint8),
    )
