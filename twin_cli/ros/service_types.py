"""gazebo_ros' and ros_gz's world services as ROS 2's rmw puts services on DDS: definitions and
DDS types.

rosbags ships no gazebo_msgs, std_srvs or ros_gz_interfaces, so the services' definitions (the
fields of their `.srv` files, and the messages they use) are registered in rosbags' typestore
through rosbags' own message parser, one message per half (`Name_Request`, `Name_Response`), as
rosidl splits a service. On DDS (rmw_cyclonedds_cpp) a service `/a` is two topics,
`rq/aRequest` and `rr/aReply`, of types `pkg::srv::dds_::Name_Request_` and `..._Response_`;
each sample starts with rmw's request header (`guid`: the client's writer, uint64; `seq`: the
request's sequence number, int64), then the message's fields, and the reply carries the
request's header back. The DDS types here are the messages' own (built from rosbags'
definitions by `graph.idl_members`) with those two members first.
"""

from __future__ import annotations

from functools import cache
from typing import Any

from twin_cli.record import messages as ros
from twin_cli.ros.graph import dds_type, idl_members

SPAWN = "gazebo_msgs/srv/SpawnEntity"
DELETE = "gazebo_msgs/srv/DeleteEntity"
MODEL_LIST = "gazebo_msgs/srv/GetModelList"
GET_STATE = "gazebo_msgs/srv/GetEntityState"
SET_STATE = "gazebo_msgs/srv/SetEntityState"
EMPTY = "std_srvs/srv/Empty"
GZ_CREATE = "ros_gz_interfaces/srv/SpawnEntity"
GZ_REMOVE = "ros_gz_interfaces/srv/DeleteEntity"
GZ_SET_POSE = "ros_gz_interfaces/srv/SetEntityPose"
GZ_CONTROL = "ros_gz_interfaces/srv/ControlWorld"
MESSAGES = {  # the messages the services carry (their `.msg` fields)
    "gazebo_msgs/msg/EntityState": """string name
geometry_msgs/Pose pose
geometry_msgs/Twist twist
string reference_frame
""",
    "ros_gz_interfaces/msg/Entity": """uint8 NONE = 0
uint8 LIGHT = 1
uint8 MODEL = 2
uint8 LINK = 3
uint8 VISUAL = 4
uint8 COLLISION = 5
uint8 SENSOR = 6
uint8 JOINT = 7
uint64 id
string name
uint8 type
""",
    "ros_gz_interfaces/msg/EntityFactory": """string name
bool allow_renaming
string sdf
string sdf_filename
string clone_name
geometry_msgs/Pose pose
string relative_to
""",
    "ros_gz_interfaces/msg/WorldReset": """bool all
bool time_only
bool model_only
""",
    "ros_gz_interfaces/msg/WorldControl": """bool pause
bool step
uint32 multi_step
ros_gz_interfaces/WorldReset reset
uint32 seed
builtin_interfaces/Time run_to_sim_time
""",
}
DEFINITIONS = {
    SPAWN: """string name
string xml
string robot_namespace
geometry_msgs/Pose initial_pose
string reference_frame
---
bool success
string status_message
""",
    DELETE: """string name
---
bool success
string status_message
""",
    MODEL_LIST: """---
std_msgs/Header header
string[] model_names
bool success
""",
    GET_STATE: """string name
string reference_frame
---
std_msgs/Header header
gazebo_msgs/EntityState state
bool success
""",
    SET_STATE: """gazebo_msgs/EntityState state
---
bool success
""",
    EMPTY: "---\n",
    GZ_CREATE: """ros_gz_interfaces/EntityFactory entity_factory
---
bool success
""",
    GZ_REMOVE: """ros_gz_interfaces/Entity entity
---
bool success
""",
    GZ_SET_POSE: """ros_gz_interfaces/Entity entity
geometry_msgs/Pose pose
---
bool success
""",
    GZ_CONTROL: """ros_gz_interfaces/WorldControl world_control
---
bool success
""",
}
REQUEST, RESPONSE = "Request", "Response"


def request_topic(service: str) -> str:
    """The DDS topic of `service`'s requests (`/spawn_entity` → `rq/spawn_entityRequest`)."""
    return f"rq/{service.lstrip('/')}Request"


def reply_topic(service: str) -> str:
    """The DDS topic of service `service`'s replies (`rr/spawn_entityReply`)."""
    return f"rr/{service.lstrip('/')}Reply"


def message_name(service_type: str, part: str) -> str:
    """The message type of one half of a service (`gazebo_msgs/srv/SpawnEntity_Request`)."""
    return f"{service_type}_{part}"


def register_service_types(store: Any) -> None:
    """Adds the services' request and response messages to a rosbags typestore (idempotent)."""
    if message_name(SPAWN, REQUEST) in store.types:
        return
    from rosbags.typesys import get_types_from_msg

    types: dict = {}
    for name, text in MESSAGES.items():
        types.update(get_types_from_msg(text, name))
    for name, text in DEFINITIONS.items():
        for part, half in zip((REQUEST, RESPONSE), text.split("---\n"), strict=True):
            parsed = get_types_from_msg(half, message_name(name, part))
            # the parser files every type under `msg/`; a service's halves live under `srv/`
            types.update({key.replace("/srv/msg/", "/srv/"): v for key, v in parsed.items()})
    store.register(types)


@cache
def service_idl(service_type: str, part: str) -> Any:
    """The cyclonedds IDL struct of one half of `service_type` as rmw_cyclonedds_cpp sends it:
    the request header (`guid`, `seq`), then the message's members."""
    from cyclonedds.idl import make_idl_struct, types

    register_service_types(ros.typestore())
    name = message_name(service_type, part)
    members = {"guid": types.uint64, "seq": types.int64, **idl_members(name)}
    return make_idl_struct(name.rsplit("/", 1)[1] + "_", dds_type(name), members)
