"""Sensor readings (`twin_cli.sensors`) as ROS messages, as gazebo_ros sensor plugins publish them.

Each kind's builder registers itself with `@ros_message(SpecType, ReadingType, ros_type)` in its
own module of `twin_cli.record.sensor_kinds` (`imu` → sensor_msgs/Imu, `ray` →
sensor_msgs/LaserScan, `force_torque` → geometry_msgs/WrenchStamped, `contact` →
gazebo_msgs/ContactsState, `camera` → sensor_msgs/Image, and any module added there), imported
the first time a type is looked up. Topics are `/<entity>/<topic>` with the sensor's `<topic>`
(or its name), plus the kind's suffix (`/image_raw` for images, as gazebo_ros' cameras).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any, TypeVar

from converters.description.sensors import SensorSpec
from twin_cli.lazy import import_modules
from twin_cli.names import namespace
from twin_cli.record import messages as ros
from twin_cli.record.topics import Message, Topic
from twin_cli.sensors import Reading

KIND_PACKAGE = "twin_cli.record.sensor_kinds"  # each of its modules registers one kind's message


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


def vector3(T: Any, v: Any) -> Any:
    """A geometry_msgs/Vector3 of the first three values of `v`, for the kinds' builders."""
    return T["geometry_msgs/msg/Vector3"](x=float(v[0]), y=float(v[1]), z=float(v[2]))
