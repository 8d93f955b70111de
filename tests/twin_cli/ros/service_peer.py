"""A ROS 2 service client that shares no code with twin, run as its own process by the tests.

It calls the world services a launch file calls: gazebo_ros' (gazebo_msgs GetEntityState,
SetEntityState; std_srvs Empty for pause, unpause and the resets) and ros_gz's
(ros_gz_interfaces SpawnEntity, DeleteEntity, SetEntityPose, ControlWorld), as
rmw_cyclonedds_cpp puts a service on DDS: topics `rq/<service>Request` and `rr/<service>Reply`,
types written here from the packages' `.srv` and `.msg` files with rmw's request header (`guid`
uint64, `seq` int64) first. The reply's bytes after the header are decoded by rosbags. Its DDS
settings and the common message types are `ros_peer`'s (the other independent peer).

Usage: python service_peer.py SERVICE KIND JSON_FIELDS
    KIND: get_state | set_state | empty | gz_create | gz_remove | gz_set_pose | gz_control
"""

# No `from __future__ import annotations`: cyclonedds reads the IDL annotations as objects.

import json
import struct
import sys
import time
from dataclasses import dataclass

from cyclonedds._clayer import ddspy_take
from cyclonedds.core import InstanceState, SampleState, ViewState
from cyclonedds.idl import IdlStruct, types
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from ros_peer import (
    Header,
    Point,
    Pose,
    Quaternion,
    Time,
    Twist,
    Vector3,
    participant,
    qos,
    to_plain,
)
from ros_peer import SpawnEntityRequest as GazeboSpawnRequest
from ros_peer import SpawnEntityResponse as GazeboSpawnResponse
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

MATCH_S = 60.0  # [s] wall for discovery to match both topics (a loaded runner is slow)
REPLY_S = 60.0  # [s] wall for the reply after that
CLIENT_GUID = 0x5EED_0000_0000_0002
SEQUENCE = 11


@dataclass
class EntityState(IdlStruct, typename="gazebo_msgs::msg::dds_::EntityState_"):
    name: str
    pose: Pose
    twist: Twist
    reference_frame: str


@dataclass
class GetEntityStateRequest(IdlStruct, typename="gazebo_msgs::srv::dds_::GetEntityState_Request_"):
    guid: types.uint64
    seq: types.int64
    name: str
    reference_frame: str


@dataclass
class GetEntityStateResponse(
    IdlStruct, typename="gazebo_msgs::srv::dds_::GetEntityState_Response_"
):
    guid: types.uint64
    seq: types.int64
    header: Header
    state: EntityState
    success: bool


@dataclass
class SetEntityStateRequest(IdlStruct, typename="gazebo_msgs::srv::dds_::SetEntityState_Request_"):
    guid: types.uint64
    seq: types.int64
    state: EntityState


@dataclass
class SetEntityStateResponse(
    IdlStruct, typename="gazebo_msgs::srv::dds_::SetEntityState_Response_"
):
    guid: types.uint64
    seq: types.int64
    success: bool


@dataclass
class EmptyRequest(IdlStruct, typename="std_srvs::srv::dds_::Empty_Request_"):
    guid: types.uint64
    seq: types.int64
    structure_needs_at_least_one_member: types.uint8 = 0


@dataclass
class EmptyResponse(IdlStruct, typename="std_srvs::srv::dds_::Empty_Response_"):
    guid: types.uint64
    seq: types.int64
    structure_needs_at_least_one_member: types.uint8 = 0


@dataclass
class Entity(IdlStruct, typename="ros_gz_interfaces::msg::dds_::Entity_"):
    id: types.uint64
    name: str
    type: types.uint8


@dataclass
class EntityFactory(IdlStruct, typename="ros_gz_interfaces::msg::dds_::EntityFactory_"):
    name: str
    allow_renaming: bool
    sdf: str
    sdf_filename: str
    clone_name: str
    pose: Pose
    relative_to: str


@dataclass
class WorldReset(IdlStruct, typename="ros_gz_interfaces::msg::dds_::WorldReset_"):
    all: bool
    time_only: bool
    model_only: bool


@dataclass
class WorldControl(IdlStruct, typename="ros_gz_interfaces::msg::dds_::WorldControl_"):
    pause: bool
    step: bool
    multi_step: types.uint32
    reset: WorldReset
    seed: types.uint32
    run_to_sim_time: Time


@dataclass
class SpawnEntityRequest(IdlStruct, typename="ros_gz_interfaces::srv::dds_::SpawnEntity_Request_"):
    guid: types.uint64
    seq: types.int64
    entity_factory: EntityFactory


@dataclass
class DeleteEntityRequest(
    IdlStruct, typename="ros_gz_interfaces::srv::dds_::DeleteEntity_Request_"
):
    guid: types.uint64
    seq: types.int64
    entity: Entity


@dataclass
class SetEntityPoseRequest(
    IdlStruct, typename="ros_gz_interfaces::srv::dds_::SetEntityPose_Request_"
):
    guid: types.uint64
    seq: types.int64
    entity: Entity
    pose: Pose


@dataclass
class ControlWorldRequest(
    IdlStruct, typename="ros_gz_interfaces::srv::dds_::ControlWorld_Request_"
):
    guid: types.uint64
    seq: types.int64
    world_control: WorldControl


@dataclass
class GzSpawnResponse(IdlStruct, typename="ros_gz_interfaces::srv::dds_::SpawnEntity_Response_"):
    guid: types.uint64
    seq: types.int64
    success: bool


@dataclass
class GzDeleteResponse(IdlStruct, typename="ros_gz_interfaces::srv::dds_::DeleteEntity_Response_"):
    guid: types.uint64
    seq: types.int64
    success: bool


@dataclass
class GzSetPoseResponse(
    IdlStruct, typename="ros_gz_interfaces::srv::dds_::SetEntityPose_Response_"
):
    guid: types.uint64
    seq: types.int64
    success: bool


@dataclass
class GzControlResponse(IdlStruct, typename="ros_gz_interfaces::srv::dds_::ControlWorld_Response_"):
    guid: types.uint64
    seq: types.int64
    success: bool


# The replies' definitions as the `.srv` files give them, for rosbags (the decoder of record).
GET_STATE_REPLY_MSG = """std_msgs/Header header
gazebo_msgs/EntityState state
bool success
"""
ENTITY_STATE_MSG = """string name
geometry_msgs/Pose pose
geometry_msgs/Twist twist
string reference_frame
"""
SUCCESS_MSG = "bool success\n"
KINDS = {  # kind → (request type, reply type, reply definition)
    "get_state": (GetEntityStateRequest, GetEntityStateResponse, GET_STATE_REPLY_MSG),
    "set_state": (SetEntityStateRequest, SetEntityStateResponse, SUCCESS_MSG),
    "empty": (EmptyRequest, EmptyResponse, "uint8 structure_needs_at_least_one_member\n"),
    "spawn": (GazeboSpawnRequest, GazeboSpawnResponse, "bool success\nstring status_message\n"),
    "gz_create": (SpawnEntityRequest, GzSpawnResponse, SUCCESS_MSG),
    "gz_remove": (DeleteEntityRequest, GzDeleteResponse, SUCCESS_MSG),
    "gz_set_pose": (SetEntityPoseRequest, GzSetPoseResponse, SUCCESS_MSG),
    "gz_control": (ControlWorldRequest, GzControlResponse, SUCCESS_MSG),
}


def _pose(fields: dict) -> Pose:
    return Pose(Point(*fields["position"]), Quaternion(*fields["orientation"]))


def _request(kind: str, fields: dict):  # noqa: ANN202 - the IDL class of `kind`
    """The request of `kind` from plain JSON fields (poses as position/orientation lists)."""
    request_type = KINDS[kind][0]
    if kind == "set_state":
        state = fields["state"]
        twist = Twist(Vector3(*state["linear"]), Vector3(*state["angular"]))
        entity = EntityState(state["name"], _pose(state["pose"]), twist, state["frame"])
        return request_type(guid=CLIENT_GUID, seq=SEQUENCE, state=entity)
    if kind == "gz_create":
        f = fields
        factory = EntityFactory(f.get("name", ""), f.get("allow_renaming", False),
                                f.get("sdf", ""), f.get("sdf_filename", ""),
                                f.get("clone_name", ""), _pose(f["pose"]),
                                f.get("relative_to", "world"))  # fmt: skip
        return request_type(guid=CLIENT_GUID, seq=SEQUENCE, entity_factory=factory)
    if kind == "spawn":
        return request_type(guid=CLIENT_GUID, seq=SEQUENCE, name=fields["name"],
                            xml=fields["xml"], robot_namespace="",
                            initial_pose=_pose(fields["pose"]), reference_frame="")  # fmt: skip
    if kind in ("gz_remove", "gz_set_pose"):
        entity = Entity(0, fields["name"], fields.get("type", 2))
        extra = {"pose": _pose(fields["pose"])} if kind == "gz_set_pose" else {}
        return request_type(guid=CLIENT_GUID, seq=SEQUENCE, entity=entity, **extra)
    if kind == "gz_control":
        reset = WorldReset(*fields.get("reset", [False, False, False]))
        sec, nanosec = fields.get("run_to", [0, 0])
        flags = fields.get("pause", False), fields.get("step", False)
        control = WorldControl(*flags, fields.get("multi_step", 0), reset, 0, Time(sec, nanosec))
        return request_type(guid=CLIENT_GUID, seq=SEQUENCE, world_control=control)
    return request_type(guid=CLIENT_GUID, seq=SEQUENCE, **fields)


def call(service: str, kind: str, fields: dict) -> dict:
    """One request once both topics are matched; the reply decoded by rosbags."""
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(ENTITY_STATE_MSG, "gazebo_msgs/msg/EntityState"))
    reply_name = f"peer_msgs/msg/{kind.title().replace('_', '')}Reply"
    store.register(get_types_from_msg(KINDS[kind][2], reply_name))
    request_type, reply_type, _ = KINDS[kind]
    dp = participant()
    name = service.lstrip("/")
    writer = DataWriter(dp, Topic(dp, f"rq/{name}Request", request_type, qos=qos()), qos=qos())
    reader = DataReader(dp, Topic(dp, f"rr/{name}Reply", reply_type, qos=qos()), qos=qos())
    deadline = time.monotonic() + MATCH_S
    while time.monotonic() < deadline and not (
        writer.get_matched_subscriptions() and reader.get_matched_publications()
    ):
        time.sleep(0.05)
    matched = bool(writer.get_matched_subscriptions() and reader.get_matched_publications())
    writer.write(_request(kind, fields))
    mask = SampleState.Any | ViewState.Any | InstanceState.Any
    while time.monotonic() < deadline + REPLY_S:
        for cdr, info in ddspy_take(reader._ref, mask, 16):
            if not info.valid_data:
                continue
            guid, seq = struct.unpack_from("<Qq", cdr, 4)
            if (guid, seq) == (CLIENT_GUID, SEQUENCE):
                reply = store.deserialize_cdr(cdr[:4] + cdr[20:], reply_name)
                return {"reply": to_plain(reply), "header": [guid, seq]}
        time.sleep(0.02)
    return {"reply": None, "matched": matched}


if __name__ == "__main__":
    json.dump(call(sys.argv[1], sys.argv[2], json.loads(sys.argv[3])), sys.stdout)
