"""The twin's node as ROS 2's graph knows nodes: its `ros_discovery_info` message.

Each rmw participant announces the nodes it holds, and every node's readers and writers by GID,
on the DDS topic `ros_discovery_info` (rmw_dds_common/ParticipantEntitiesInfo; reliable,
transient local, keep last 1), which `ros2 node list` and `ros2 node info` read. A GID is the
entity's 16-byte DDS GUID, zero-padded to the distribution's GID size (`distro`: 24 bytes in
Humble, 16 from Iron on), and the message's `Gid` type has that size too, or the distribution's
readers would not match. The twin is two nodes, each in a participant of its own: `/twin`,
whose writers are the world's topics (the publisher process), and `/twin_commands`, whose
readers are the drives' `cmd_vel` and the controllers' topics (the server).
"""

from __future__ import annotations

from functools import cache
from typing import Any

from twin_cli.ros.distro import GID_SIZES, gid

DISCOVERY_TOPIC = "ros_discovery_info"  # no `rt/`: an rmw topic, not a ROS one
INFO = "rmw_dds_common/msg/ParticipantEntitiesInfo"
NODE_NAME = "twin"  # the world's topics
COMMANDS_NODE_NAME = "twin_commands"  # what the twin reads
NODE_NAMESPACE = "/"
NAME_BOUND = 256  # NodeEntitiesInfo's string<256> node_namespace and node_name
DDS_PREFIX = "rmw_dds_common::msg::dds_::"


def info_type(distro: str) -> Any:
    """ParticipantEntitiesInfo as a cyclonedds IDL struct of `distro`'s rmw_dds_common."""
    return _types(distro)[2]


@cache
def _types(distro: str) -> tuple[Any, Any, Any]:
    """rmw_dds_common's Gid, NodeEntitiesInfo and ParticipantEntitiesInfo as cyclonedds IDL
    structs of `distro` (`Gid.msg`: `char[N] data`, N = GID_SIZES[distro]; char is an octet)."""
    from cyclonedds.idl import make_idl_struct, types

    gid_type = make_idl_struct(
        "Gid_", DDS_PREFIX + "Gid_", {"data": types.array[types.uint8, GID_SIZES[distro]]}
    )
    node = make_idl_struct(
        "NodeEntitiesInfo_",
        DDS_PREFIX + "NodeEntitiesInfo_",
        {
            "node_namespace": types.bounded_str[NAME_BOUND],
            "node_name": types.bounded_str[NAME_BOUND],
            "reader_gid_seq": types.sequence[gid_type],
            "writer_gid_seq": types.sequence[gid_type],
        },
    )
    info = make_idl_struct(
        "ParticipantEntitiesInfo_",
        DDS_PREFIX + "ParticipantEntitiesInfo_",
        {"gid": gid_type, "node_entities_info_seq": types.sequence[node]},
    )
    return gid_type, node, info


def discovery_info(
    distro: str,
    participant: bytes,
    readers: list[bytes],
    writers: list[bytes],
    name: str = NODE_NAME,
) -> Any:
    """The participant's ParticipantEntitiesInfo sample (`info_type(distro)`): one node,
    `name`, with those readers and writers (DDS GUIDs of 16 bytes each)."""
    gid_type, node_type, info = _types(distro)

    def as_gid(guid: bytes) -> Any:
        return gid_type(data=list(gid(guid, distro)))

    node = node_type(
        node_namespace=NODE_NAMESPACE,
        node_name=name,
        reader_gid_seq=[as_gid(r) for r in readers],
        writer_gid_seq=[as_gid(w) for w in writers],
    )
    return info(gid=as_gid(participant), node_entities_info_seq=[node])
