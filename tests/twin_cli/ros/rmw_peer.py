"""A ROS 2 peer whose Cyclone DDS domain is configured as rmw_cyclonedds_cpp configures its own.

The XML is written here from rmw_cyclonedds_cpp's rules (`check_create_domain` in rmw_node.cpp)
and rcl's reading of the variables, not from twin's code:
- Humble: `ROS_LOCALHOST_ONLY=1` gives `<NetworkInterface address="127.0.0.1"/>`; otherwise
  nothing (Cyclone's own choice of interface, multicast).
- Jazzy (rcl 9.2): `ROS_LOCALHOST_ONLY=1` means the LOCALHOST range without static peers;
  `ROS_AUTOMATIC_DISCOVERY_RANGE` (unset: SUBNET) and `ROS_STATIC_PEERS` (`;`-separated):
  SUBNET adds the peers (ParticipantIndex auto, MaxAutoParticipantIndex 32) and keeps
  multicast; LOCALHOST turns multicast off and adds `localhost` then the peers; OFF turns
  multicast off with ParticipantIndex none and a domain tag of its own; SYSTEM_DEFAULT
  changes nothing.

It reads the graph as that distribution's `ros2 node list` does: `ros_discovery_info` typed
from that distribution's rmw_dds_common (`Gid.msg`: `char[24] data` in Humble, `char[16] data`
in Jazzy; rmw's GID size, RMW_GID_STORAGE_SIZE), and each participant's USER_DATA, where rmw
puts `enclave=<enclave>;`.

Usage: python rmw_peer.py humble|jazzy session SECONDS ENTITY VX
(counts /clock for SECONDS while sending Twist(VX) on /ENTITY/cmd_vel every 0.1 s; prints
{"clock": received, "sent": ..., "matched": cmd_vel readers matched, "config": the XML})
| graph SECONDS (prints {"nodes": [[namespace, name, [GID sizes]]], "user_data": [...]}).
"""

import faulthandler
import json
import os
import sys
import time
from dataclasses import dataclass

import ros_peer
from cyclonedds.builtin import BuiltinDataReader, BuiltinTopicDcpsParticipant
from cyclonedds.idl import IdlStruct, types
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

MAX_AUTO_PARTICIPANT_INDEX = 32  # rmw_cyclonedds_cpp's fixed value
STUCK_S = 60.0  # [s] a run longer than this is stuck (a session takes its SECONDS and ~1 s)


@dataclass
class HumbleGid(IdlStruct, typename="rmw_dds_common::msg::dds_::Gid_"):
    data: types.array[types.uint8, 24]


@dataclass
class HumbleNodeEntitiesInfo(IdlStruct, typename="rmw_dds_common::msg::dds_::NodeEntitiesInfo_"):
    node_namespace: types.bounded_str[256]
    node_name: types.bounded_str[256]
    reader_gid_seq: types.sequence[HumbleGid]
    writer_gid_seq: types.sequence[HumbleGid]


@dataclass
class HumbleParticipantEntitiesInfo(
    IdlStruct, typename="rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_"
):
    gid: HumbleGid
    node_entities_info_seq: types.sequence[HumbleNodeEntitiesInfo]


def humble_config(env: dict) -> str:
    if env.get("ROS_LOCALHOST_ONLY", "") == "1":
        return (
            '<CycloneDDS><Domain><General><Interfaces><NetworkInterface address="127.0.0.1"/>'
            "</Interfaces></General></Domain></CycloneDDS>"
        )
    return ""


def jazzy_config(env: dict) -> str:
    localhost_only = env.get("ROS_LOCALHOST_ONLY", "")[:1] == "1"
    wanted = "LOCALHOST" if localhost_only else env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "")
    wanted = wanted or "SUBNET"
    if wanted not in ("OFF", "LOCALHOST", "SUBNET", "SYSTEM_DEFAULT"):
        wanted = "LOCALHOST"  # rcl: "Invalid value ..., assuming localhost only"
    peers = [] if localhost_only or wanted == "OFF" else env.get("ROS_STATIC_PEERS", "")
    peers = [p for p in peers.split(";") if p] if peers else []
    localhost, add_peers, no_multicast = {
        "SUBNET": (False, True, False),
        "SYSTEM_DEFAULT": (False, False, False),
        "LOCALHOST": (True, True, True),
        "OFF": (False, False, True),
    }[wanted]
    if not (localhost or add_peers or no_multicast):
        return ""
    config = "<CycloneDDS><Domain>"
    if no_multicast:
        config += "<General><AllowMulticast>false</AllowMulticast></General>"
    if no_multicast and not localhost and not add_peers:
        config += "<Discovery><ParticipantIndex>none</ParticipantIndex>"
        config += f"<Tag>ros_discovery_off_{os.getpid()}</Tag>"
    else:
        config += "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
        config += f"<MaxAutoParticipantIndex>{MAX_AUTO_PARTICIPANT_INDEX}</MaxAutoParticipantIndex>"
    if (add_peers and peers) or localhost:
        config += "<Peers>"
        if localhost:
            config += '<Peer address="localhost"/>'
        config += "".join(f'<Peer address="{p}"/>' for p in peers)
        config += "</Peers>"
    return config + "</Discovery></Domain></CycloneDDS>"


def session(seconds: float, entity: str, vx: float) -> dict:
    """/clock samples taken in `seconds`, while a Twist (vx [m/s]) goes out every 0.1 s."""
    dp = ros_peer.participant()
    qos = ros_peer.qos()
    clock = DataReader(dp, Topic(dp, "rt/clock", ros_peer.Clock, qos=qos), qos=qos)
    topic = Topic(dp, f"rt/{entity}/cmd_vel", ros_peer.Twist, qos=qos)
    writer = DataWriter(dp, topic, qos=qos)
    twist = ros_peer.Twist(ros_peer.Vector3(vx, 0.0, 0.0), ros_peer.Vector3(0.0, 0.0, 0.0))
    received, sent, end = 0, 0, time.monotonic() + seconds
    while time.monotonic() < end:
        received += len(clock.take(64))
        writer.write(twist)
        sent += 1
        time.sleep(0.1)
    return {"clock": received, "sent": sent, "matched": len(writer.get_matched_subscriptions())}


def graph(seconds: float, distro: str) -> dict:
    """The nodes `ros_discovery_info` names, with their GIDs' sizes, and the participants'
    USER_DATA (but this peer's), gathered for `seconds`."""
    dp = ros_peer.participant()
    kind = HumbleParticipantEntitiesInfo if distro == "humble" else ros_peer.ParticipantEntitiesInfo
    latched = ros_peer.qos(latched=True, depth=100)
    info = DataReader(dp, Topic(dp, "ros_discovery_info", kind, qos=latched), qos=latched)
    participants = BuiltinDataReader(dp, BuiltinTopicDcpsParticipant)
    nodes, user_data, end = set(), set(), time.monotonic() + seconds
    while time.monotonic() < end:
        for sample in info.take(64):
            gids = [sample.gid] + [
                g for n in sample.node_entities_info_seq
                for g in (*n.reader_gid_seq, *n.writer_gid_seq)
            ]  # fmt: skip
            sizes = sorted({len(g.data) for g in gids})
            for node in sample.node_entities_info_seq:
                nodes.add((node.node_namespace, node.node_name, tuple(sizes)))
        for sample in participants.take(64):
            if sample.key == dp.guid:  # this peer itself
                continue
            data = sample.qos[ros_peer.Policy.Userdata]
            user_data.add(data.data.decode("latin-1") if data is not None else None)
        time.sleep(0.05)
    return {"nodes": sorted(nodes), "user_data": sorted(user_data, key=str)}


if __name__ == "__main__":
    faulthandler.dump_traceback_later(STUCK_S, exit=True)  # a stuck peer says where, and ends
    distro, command, *args = sys.argv[1:]
    ros_peer.CONFIG = (humble_config if distro == "humble" else jazzy_config)(dict(os.environ))
    if command == "graph":
        result = graph(float(args[0]), distro)
    else:
        result = session(float(args[0]), args[1], float(args[2]))
    result["config"] = ros_peer.CONFIG
    json.dump(result, sys.stdout)
    sys.stdout.flush()
    os._exit(0)  # the result is out: no teardown of Cyclone's threads to wait on
