"""How the world's ROS topics appear on DDS: names, types and QoS as ROS 2's rmw layers map them.

The topics themselves (names, message types, which are latched) are the recorder's
(`twin_cli.record.topics`, `sensor_messages`); this module only maps them onto DDS:

- topic `/a/b` is DDS topic `rt/a/b`; message type `pkg/msg/Name` is DDS type
  `pkg::msg::dds_::Name_`, and its nested types likewise;
- QoS as ROS's own publishers offer them (`twin_cli.record.qos`, which a bag's channels
  carry too): reliable, volatile, keep last 10 (rclcpp's default); latched topics
  (`/tf_static`, `robot_description`) reliable, transient local, keep last 1 (tf2's static
  broadcaster, robot_state_publisher); sensor topics best effort, keep last 5 (rclcpp's
  SensorDataQoS, which gazebo_ros' sensor plugins use);
- each endpoint's user data carries `typehash=RIHS01_<hex>;`, as Jazzy's rmw puts it there.

The DDS types are built from rosbags' definitions of each message (`idl_type`), so no message
is written by hand; twin sends rosbags' CDR bytes as they are and reads commands with rosbags.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from twin_cli.record import messages as ros
from twin_cli.record.qos import (  # noqa: F401 (the bridge's modules take them from here)
    DEFAULT_QOS,
    LATCHED_QOS,
    SENSOR_QOS,
    Qos,
    qos_of,
)

TWIST = "geometry_msgs/msg/Twist"
TWIST_STAMPED = "geometry_msgs/msg/TwistStamped"
FLOAT64_ARRAY = "std_msgs/msg/Float64MultiArray"
_EMPTY_MEMBER = "structure_needs_at_least_one_member"  # rosidl's member of an empty message


def dds_topic(name: str) -> str:
    """The DDS topic of ROS topic `name` (`/a/b` → `rt/a/b`)."""
    return "rt/" + name.lstrip("/")


def dds_type(name: str) -> str:
    """The DDS type of message type `name` (`pkg/msg/Name` → `pkg::msg::dds_::Name_`)."""
    package, kind, message = name.split("/")
    return f"{package}::{kind}::dds_::{message}_"


def user_data(name: str) -> bytes:
    """An endpoint's USER_DATA for message type `name`: its RIHS01 type hash, as Jazzy's."""
    return f"typehash={ros.definition(name).rihs01};".encode()


def dds_qos(qos: Qos, name: str | None) -> Any:
    """`qos` as a cyclonedds Qos for an endpoint of message type `name` (plain CDR, XCDR1, as
    rmw_cyclonedds_cpp writes it); `name` None: no type hash (a service's halves: rmw hashes
    the service's whole description, which rosbags does not build)."""
    from cyclonedds.qos import Policy
    from cyclonedds.qos import Qos as CycloneQos

    reliability = (
        Policy.Reliability.Reliable(max_blocking_time=0)
        if qos.reliable
        else Policy.Reliability.BestEffort
    )
    durability = (
        Policy.Durability.TransientLocal if qos.transient_local else Policy.Durability.Volatile
    )
    policies = [
        reliability,
        durability,
        Policy.History.KeepLast(qos.depth),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    ]
    if name is not None:
        policies.append(Policy.Userdata(user_data(name)))
    return CycloneQos(*policies)


@cache
def idl_type(name: str) -> Any:
    """A cyclonedds IDL struct of message type `name`, built from rosbags' definition: its DDS
    type name and members, nested types included, as rosidl generates them."""
    from cyclonedds.idl import make_idl_struct

    return make_idl_struct(name.rsplit("/", 1)[1] + "_", dds_type(name), idl_members(name))


def idl_members(name: str) -> dict[str, Any]:
    """The IDL members of message type `name` (rosidl's one uint8 for an empty message)."""
    _, fields = ros.typestore().fielddefs[name]
    members = {field: _member(node, detail) for field, (node, detail) in fields}
    if not members:
        members[_EMPTY_MEMBER] = _base("uint8")
    return members


def _member(node: int, detail: Any) -> Any:
    """The IDL type of one field (rosbags' Nodetype: 1 base, 2 message, 3 array, 4 sequence)."""
    from cyclonedds.idl import types

    if node == 1:
        name, bound = detail
        return types.bounded_str[bound] if name == "string" and bound else _base(name)
    if node == 2:
        return idl_type(detail)
    (inner_node, inner), length = detail
    if node == 3:
        return types.array[_member(inner_node, inner), length]
    inner_type = _member(inner_node, inner)  # bounded sequences keep their bound (type match)
    return types.sequence[inner_type, length] if length else types.sequence[inner_type]


def _base(name: str) -> Any:
    """ROS's primitive types as rosidl maps them to IDL (byte and char are octets)."""
    from cyclonedds.idl import types

    table = {
        "bool": bool,
        "byte": types.uint8,
        "char": types.uint8,
        "float32": types.float32,
        "float64": types.float64,
        "string": str,
    }
    return table.get(name) or getattr(types, name)
