"""The ROS 2 message types twin publishes: their definitions and CDR encoding (rosbags).

`rosbags` ships the message definitions of each ROS 2 distribution and a generated CDR
serializer for each type, so nothing here writes definitions or encodes CDR by hand. The
definitions are Jazzy's (the LTS distribution); the types used are unchanged since Humble.
"""

from __future__ import annotations

import struct
import sys
from dataclasses import dataclass
from functools import cache
from typing import Any

from twin_cli.record.contact_types import register_contact_types

CLOCK = "rosgraph_msgs/msg/Clock"
TF = "tf2_msgs/msg/TFMessage"
JOINT_STATE = "sensor_msgs/msg/JointState"
STRING = "std_msgs/msg/String"
ODOMETRY = "nav_msgs/msg/Odometry"
DISTRO = "jazzy"


@dataclass(frozen=True)
class Definition:
    """One message type as rosbag2 stores it.

    Attributes:
        name: `pkg/msg/Type`; schema_name: `pkg/msg/Type` (rosbag2 and Foxglove use this form).
        text: the `ros2msg` definition with its dependencies (the MCAP schema data).
        rihs01: the type description hash (rosbag2 ≥ Iron stores it per topic).
    """

    name: str
    text: str
    rihs01: str


@cache
def typestore() -> Any:
    """rosbags' typestore of the ROS 2 distribution twin writes for (built once, ~0.1 s)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_JAZZY)
    register_contact_types(store)  # gazebo_msgs, for contact sensors
    return store


@cache
def definition(name: str) -> Definition:
    """The stored definition of message type `name` (`pkg/msg/Type`)."""
    store = typestore()
    text, _ = store.generate_msgdef(name, ros_version=2)
    return Definition(name, text, store.hash_rihs01(name))


def types() -> Any:
    """The message classes by name (`types()[JOINT_STATE](header=..., ...)`)."""
    return typestore().types


def encode(message: Any, name: str) -> bytes:
    """The CDR bytes of `message` (a `types()[name]` instance)."""
    return bytes(typestore().serialize_cdr(message, name))


class Reencoder:
    """The CDR encoding of one message object that is refilled in place and keeps its size.

    The live messages of a layout (`live_messages`) keep their names, frame ids and array
    lengths; only numbers change. `encode` sizes every message before serializing it (for a
    humanoid's `/tf`, a fifth of its time), so this keeps the buffer of the first encoding and
    calls rosbags' generated serializer of the type into it. A message whose size did change is
    encoded again the usual way, with a new buffer. Strings must not change: rosbags writes
    neither their terminating NUL nor padding (its fresh buffers are zeroed), so a string
    changed to another of the same length could leave a stale byte.
    """

    def __init__(self, message: Any, name: str) -> None:
        self._message, self._name = message, name
        self._store = typestore()
        msgdef = self._store.get_msgdef(name)
        little = sys.byteorder == "little"
        self._serialize = msgdef.serialize_cdr_le if little else msgdef.serialize_cdr_be
        self._resize()

    def __call__(self) -> bytes:
        """The CDR bytes of the message as it is now."""
        try:
            end = self._serialize(self._body, 0, self._message, self._store)
        except (struct.error, ValueError):  # grew: it no longer fits the buffer
            end = -1
        if end != len(self._body):
            self._resize()
        return bytes(self._buffer)

    def _resize(self) -> None:
        self._buffer = bytearray(encode(self._message, self._name))  # header and size: rosbags'
        self._body = memoryview(self._buffer)[4:]


def stamp(time: float) -> Any:
    """builtin_interfaces/Time of sim `time` [s], rounded to the nanosecond."""
    sec, nanosec = divmod(round(time * 1e9), 1_000_000_000)
    return types()["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)


def nanoseconds(time: float) -> int:
    """Sim `time` [s] in integer nanoseconds (MCAP log and publish times)."""
    return round(time * 1e9)
