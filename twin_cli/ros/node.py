"""The twin's node as ROS 2's graph knows nodes: its `ros_discovery_info` message.

Each rmw participant announces the nodes it holds, and every node's readers and writers by GID,
on the DDS topic `ros_discovery_info` (rmw_dds_common/ParticipantEntitiesInfo; reliable,
transient local, keep last 1), which `ros2 node list` and `ros2 node info` read. A GID is the
entity's 16-byte DDS GUID (Jazzy's Gid; Humble's holds 24 bytes). The twin is two nodes, each
in a participant of its own: `/twin`, whose writers are the world's topics (the publisher
process), and `/twin_commands`, whose readers are the drives' `cmd_vel` and the controllers'
topics (the server).
"""

from __future__ import annotations

import numpy as np

from twin_cli.record import messages as ros

DISCOVERY_TOPIC = "ros_discovery_info"  # no `rt/`: an rmw topic, not a ROS one
INFO = "rmw_dds_common/msg/ParticipantEntitiesInfo"
NODE_NAME = "twin"  # the world's topics
COMMANDS_NODE_NAME = "twin_commands"  # what the twin reads
NODE_NAMESPACE = "/"


def discovery_info(
    participant: bytes, readers: list[bytes], writers: list[bytes], name: str = NODE_NAME
) -> bytes:
    """The CDR bytes of the participant's ParticipantEntitiesInfo: one node, `name`, with
    those readers and writers (GUIDs of 16 bytes each)."""
    T = ros.types()

    def gid(guid: bytes) -> object:
        return T["rmw_dds_common/msg/Gid"](data=np.frombuffer(guid, dtype=np.uint8).copy())

    node = T["rmw_dds_common/msg/NodeEntitiesInfo"](
        node_namespace=NODE_NAMESPACE,
        node_name=name,
        reader_gid_seq=[gid(r) for r in readers],
        writer_gid_seq=[gid(w) for w in writers],
    )
    return ros.encode(T[INFO](gid=gid(participant), node_entities_info_seq=[node]), INFO)
