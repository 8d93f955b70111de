"""`twin serve --ros` seen and driven from another process over loopback DDS, as a ROS 2 node
would: a real server, and a peer (`ros_peer.py`) that shares no code with twin, types its
topics from the official `.msg` definitions and decodes the received bytes with rosbags.

Each test module runs in a domain of its own (ROS_DOMAIN_ID), so parallel runs never meet; the
Cyclone configuration on both sides is loopback only, so nothing leaves the machine.
"""

from __future__ import annotations

import json
import math
import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import drive_models as dm
import numpy as np
import pytest
from models import CONTROL_RIG
from ros_cli import ros_env, script_json, twin_ok
from sensor_models import lidar_post
from sock_diag import sockets_of

pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
# One worker runs the module: its server and peers share one domain, of this process's own.
pytestmark = pytest.mark.xdist_group("ros_live")

WORLD = "ros_live"
PEER = Path(__file__).with_name("ros_peer.py")
# One domain per test process, 30-69: its ports (7400 + 250·id + ...) stay below Linux's
# ephemeral range (32768 on), so no client socket of another program can hold one.
DOMAIN_ID = str(30 + os.getpid() % 40)
DDS_BASE_PORT = 7400  # DDSI's port base: domain d uses 7400 + 250·d onwards
STATE_PERIOD = 0.01  # [s] of sim time between /clock, /tf and joint_states messages (100 Hz)
POSE_TOL = 1e-9  # [m, rad] tf composed against `twin model`: the same numbers, two routes
DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><odometry_frame>odom"
    "</odometry_frame><robot_base_frame>base_link</robot_base_frame></plugin>"
)


def _env(runtime: Path) -> dict[str, str]:
    return ros_env(runtime, DOMAIN_ID)


def _twin(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, DOMAIN_ID, WORLD, *args)


def _peer(runtime: Path, *args: str) -> dict:
    return script_json(PEER, runtime, DOMAIN_ID, *args)


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A world served with --ros (running in real time) and two diff-drive bases on the ground."""
    root = tmp_path_factory.mktemp("ros_live")
    path = root / "base.urdf"
    path.write_text(dm.two_wheel_base(DIFF))
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ROS_DOMAIN_ID", DOMAIN_ID)
        patch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
        with serve_world(root, WORLD, "--ros", "--ros-services") as (_, proc):
            for name, y in (("bot", 0.0), ("twin_bot", 2.0)):
                _twin(root, "spawn", str(path), "--name", name, "-y", str(y), "--on-ground")
            post = root / "post.urdf"
            post.write_text(lidar_post(rate=10.0))
            _twin(root, "spawn", str(post), "--name", "post", "-x", "3", "-y", "-2")
            rig = root / "rig.urdf"
            rig.write_text(CONTROL_RIG)
            _twin(root, "spawn", str(rig), "--name", "rig", "-x", "-3")
            yield root, proc


def test_clock_advances_in_sim_time_at_the_stated_rate(served) -> None:
    root, _ = served
    got = _peer(root, "listen", "2", "bot")
    clocks = [
        m["clock"]["sec"] + m["clock"]["nanosec"] * 1e-9 for _, m in got["messages"]["/clock"]
    ]
    assert len(clocks) >= 50, f"/clock: {len(clocks)} messages in 2 s of wall time"
    steps = np.diff(clocks) / STATE_PERIOD
    assert np.all(steps > 0.5), f"/clock went back or repeated: steps {steps.min()} periods"
    assert np.allclose(steps, np.round(steps), atol=1e-6), "/clock off its 100 Hz grid"
    assert np.median(steps) == pytest.approx(1.0), "/clock: most messages 10 ms of sim time apart"
    assert got["types"]["/clock"] == "rosgraph_msgs::msg::dds_::Clock_"
    status = json.loads(_twin(root, "ros", "status", "--json"))
    assert status["stride"] == 1, f"a real-time world observed at 1/{status['stride']} the rate"


def test_tf_and_joint_states_match_twin_model_and_twin_joints(served) -> None:
    """Read while the world pauses: its /tf goes once at the paused time (tf2 refuses a stamp
    twice), so the listener joins before the pause; joint_states are sent again every 0.5 s."""
    root, _ = served
    peer = subprocess.Popen(
        [sys.executable, str(PEER), "listen", "3.5", "bot"],
        env=_env(root), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    time.sleep(2.0)  # the peer's start (about 1 s) and a running world
    _twin(root, "pause")
    try:
        out, err = peer.communicate(timeout=120)
        model = json.loads(_twin(root, "model", "bot", "--json"))
        joints = json.loads(_twin(root, "joints", "bot", "--json"))
    finally:
        _twin(root, "resume")
    assert peer.returncode == 0, f"ros_peer listen: {err[-2000:]}"
    messages = json.loads(out)["messages"]
    assert messages["/tf"] and messages["/bot/joint_states"], "no /tf or joint_states received"
    edges = {}
    for key in ("/tf_static", "/tf"):  # late joiner: /tf_static arrives transient-local
        for transform in messages[key][-1][1]["transforms"]:
            edges[transform["child_frame_id"]] = transform
    for frame in model["frames"]:
        position, quat = _world_pose(frame["name"], edges)
        expected = frame["pose"]
        for axis, value in zip("xyz", position, strict=True):
            assert value == pytest.approx(expected[axis], abs=POSE_TOL), f"{frame['name']} {axis}"
        assert _same_rotation(quat, expected["quat"]), f"{frame['name']} rotation"
    state = messages["/bot/joint_states"][-1][1]
    for joint in joints:
        i = state["name"].index(joint["name"])
        for field in ("position", "velocity", "effort"):
            assert state[field][i] == pytest.approx(joint[field], abs=1e-12), (joint["name"], field)
    assert messages["/bot/robot_description"], "robot_description not sent to a late joiner"
    assert messages["/bot/odom"][-1][1]["child_frame_id"] == "bot/base_link"


def test_the_nodes_are_announced_as_ros2_node_list_reads_them(served) -> None:
    """ros_discovery_info (transient local) names node /twin with a writer per published topic
    (the publisher process's participant) and /twin_commands with a reader per input and the
    entity services' readers and writers (the server's)."""
    root, _ = served
    got = _peer(root, "listen", "1", "bot")
    infos = [m for _, m in got["messages"]["ros_discovery_info"]]
    nodes = {}
    for info in infos:
        for n in info["node_entities_info_seq"]:
            nodes[(n["node_namespace"], n["node_name"])] = n
    assert ("/", "twin") in nodes and ("/", "twin_commands") in nodes, f"nodes: {list(nodes)}"
    twin, commands = nodes[("/", "twin")], nodes[("/", "twin_commands")]
    assert len(twin["writer_gid_seq"]) >= 9, "writers: 3 world topics + 3 per bot, ..."
    assert not twin["reader_gid_seq"], "the publisher reads nothing"
    services = 13  # gazebo_ros' 9 and ros_gz's 4 world services
    readers = 2 * 2 + 4 + services  # per bot: Twist (its plugin's one type), forward
    # velocity; rig: 3 + trajectory; a request reader per service
    assert len(commands["reader_gid_seq"]) == readers, "a reader per input"
    assert len(commands["writer_gid_seq"]) == services, "a reply writer per service"
    gids = twin["writer_gid_seq"] + commands["reader_gid_seq"]
    assert all(len(g["data"]) == 16 for g in gids), "GIDs of 16 bytes"


def test_a_twist_on_cmd_vel_drives_the_base_as_twin_drive_does(served) -> None:
    """bot gets (0.2 m/s, 0.5 rad/s) over DDS, twin_bot the same from `twin drive`, in one
    paused world stepped 2 s: their paths agree to 1e-6 (measured: 1e-13), and follow the
    unicycle's arc (0.337, 0.184) m, 1 rad within 10 % (measured: 0.336, 0.177 m, 0.98 rad)."""
    root, _ = served
    _twin(root, "pause")
    start = {n: json.loads(_twin(root, "pose", n, "--json")) for n in ("bot", "twin_bot")}
    sent = _peer(root, "drive", "bot", "0.2", "0.5", "0.6")
    assert sent["matched"] == 1, "the twin's cmd_vel reader did not match the peer's writer"
    status = json.loads(_twin(root, "ros", "status", "--json"))
    assert status["commands"] >= 1 and "/bot/cmd_vel" in status["inputs"], status
    _twin(root, "drive", "twin_bot", "--linear", "0.2", "--angular", "0.5")
    _twin(root, "step", "2000")
    end = {n: json.loads(_twin(root, "pose", n, "--json")) for n in ("bot", "twin_bot")}
    _twin(root, "resume")
    moved = {n: _moved(start[n], end[n]) for n in end}
    for got, same in zip(moved["bot"], moved["twin_bot"], strict=True):
        assert got == pytest.approx(same, abs=1e-6), f"cmd_vel {moved['bot']} vs drive {same}"
    x, y, yaw = moved["bot"]
    arc = (0.2 / 0.5 * math.sin(1.0), 0.2 / 0.5 * (1 - math.cos(1.0)))  # 2 s at 0.5 rad/s
    assert yaw == pytest.approx(1.0, rel=0.1), f"heading turned {yaw} rad, unicycle 1.0"
    assert math.hypot(x - arc[0], y - arc[1]) < 0.1 * 0.4, f"({x}, {y}) vs unicycle {arc}"


def test_a_newer_twist_on_cmd_vel_replaces_the_last(served) -> None:
    """0.1 m/s straight replaces the turning command of the test before; over 1 s the base
    goes ~0.1 m and barely turns. (A TwistStamped on this topic matches no reader: the
    plugin subscribes Twist alone, `test_ros_conventions`.)"""
    root, _ = served
    _twin(root, "pause")
    before = json.loads(_twin(root, "ros", "status", "--json"))["commands"]
    start = json.loads(_twin(root, "pose", "bot", "--json"))
    sent = _peer(root, "drive", "bot", "0.1", "0.0", "0.6")
    assert sent["matched"] == 1, "the twin's Twist reader did not match"
    assert json.loads(_twin(root, "ros", "status", "--json"))["commands"] > before
    _twin(root, "step", "1000")
    end = json.loads(_twin(root, "pose", "bot", "--json"))
    _twin(root, "resume")
    forward, _, turned = _moved(start, end)
    assert 0.05 < forward < 0.15, f"went {forward} m in 1 s at 0.1 m/s"
    assert abs(turned) < 0.1, f"turned {turned} rad (the former command turns 0.5 rad/s)"


def test_a_lidar_is_published_best_effort_at_its_rate(served) -> None:
    """`/post/scan` (sensor_msgs/LaserScan) comes to a best-effort subscriber, in the sensor's
    frame, ~10 a second (10 Hz of sim time in real time)."""
    root, _ = served
    scans = _peer(root, "scan", "1.5", "/post/scan")["scans"]
    assert len(scans) >= 5, f"{len(scans)} scans in 1.5 s"
    assert scans[-1]["header"]["frame_id"] == "post/scan"
    assert len(scans[-1]["ranges"]) == 181
    stamps = [s["header"]["stamp"]["sec"] + s["header"]["stamp"]["nanosec"] * 1e-9 for s in scans]
    assert np.allclose(np.diff(stamps) / 0.1, np.round(np.diff(stamps) / 0.1), atol=1e-6)


def test_forward_controller_commands_set_the_joint_targets(served) -> None:
    """Float64MultiArray on /rig/forward_<mode>_controller/commands: one target per joint
    offering that mode, in `twin joints` order; `twin joints` then shows them held."""
    root, _ = served
    sent = _peer(root, "forward", "rig", "velocity", "0.6", "1.5")
    assert sent["matched"] == 1, "the twin's forward command reader did not match"
    sent = _peer(root, "forward", "rig", "position", "0.6", "0.2")
    assert sent["matched"] == 1
    held = {j["name"]: j for j in json.loads(_twin(root, "joints", "rig", "--json"))}
    assert (held["spin"]["mode"], held["spin"]["target"]) == ("velocity", 1.5), held["spin"]
    assert (held["slide"]["mode"], held["slide"]["target"]) == ("position", 0.2), held["slide"]


def _slide_reaches(root: Path, entity: str, target: float) -> float:
    """The `slide` joint's position [m] once within 5 mm of `target`, or after 3 s of wall."""
    deadline, position = time.monotonic() + 3.0, float("nan")
    while time.monotonic() < deadline:
        joints = {j["name"]: j for j in json.loads(_twin(root, "joints", entity, "--json"))}
        position = joints["slide"]["position"]
        if abs(position - target) < 0.005:
            break
        time.sleep(0.2)
    return position


def test_a_joint_trajectory_moves_the_joint_there(served) -> None:
    """trajectory_msgs/JointTrajectory on /rig/joint_trajectory_controller/joint_trajectory
    (slide to 0.1 m in 0.5 s) is followed as `twin trajectory` follows one: the joint gets
    there (5 mm: the servo's tracking) within 3 s of wall time."""
    root, _ = served
    sent = _peer(root, "trajectory", "rig", "slide", "0.1", "0.5")
    assert sent["matched"] == 1, "the twin's JointTrajectory reader did not match"
    position = _slide_reaches(root, "rig", 0.1)
    assert position == pytest.approx(0.1, abs=0.005), f"slide at {position} m"


def _names(root: Path) -> list[str]:
    return [e["name"] for e in json.loads(_twin(root, "list", "--json"))]


def test_gazebo_ros_entity_services_spawn_list_and_delete_as_the_cli_does(served) -> None:
    """/spawn_entity, /get_model_list and /delete_entity called as an rmw_cyclonedds client
    calls them (rmw's request header echoed in each reply): the spawned entity is where the
    request put it (yaw 90 degrees, relative to the world, then to another entity); a refused
    request (a taken name, an unknown reference frame, an unknown entity) says why and leaves
    the world as it was."""
    root, _ = served
    listed = _peer(root, "call", "/get_model_list", "{}")
    assert listed["header"] == [0x5EED_0000_0000_0001, 7], "reply without the request's header"
    initial = _names(root)
    assert listed["reply"]["success"] and listed["reply"]["model_names"] == initial
    xml = dm.two_wheel_base("")
    half = math.sqrt(0.5)
    pose = {"position": [4.0, -4.0, 0.3], "orientation": [0.0, 0.0, half, half]}
    request = {"name": "svc_bot", "xml": xml, "robot_namespace": "", "initial_pose": pose,
               "reference_frame": "world"}  # fmt: skip
    spawned = _peer(root, "call", "/spawn_entity", json.dumps(request))["reply"]
    assert spawned["success"], spawned
    at = json.loads(_twin(root, "pose", "svc_bot", "--json"))
    assert (at["x"], at["y"]) == pytest.approx((4.0, -4.0), abs=0.02), f"spawned at {at}"
    assert at["yaw"] == pytest.approx(math.pi / 2, abs=0.02), f"spawned with yaw {at['yaw']}"
    before = _names(root)
    again = _peer(root, "call", "/spawn_entity", json.dumps(request))["reply"]
    assert not again["success"] and "svc_bot" in again["status_message"], again
    unknown = {**request, "name": "svc_other", "reference_frame": "no_such_frame"}
    refused = _peer(root, "call", "/spawn_entity", json.dumps(unknown))["reply"]
    assert not refused["success"] and "no_such_frame" in refused["status_message"], refused
    malformed = {**request, "name": "svc_bad", "xml": "<robot name='svc_bad'><link name="}
    broken = _peer(root, "call", "/spawn_entity", json.dumps(malformed))["reply"]
    assert not broken["success"] and broken["status_message"], f"bad XML answered: {broken}"
    assert _names(root) == before, "a refused spawn changed the world"
    ahead_1m = {"position": [1.0, 0.0, 0.0], "orientation": [0.0, 0.0, 0.0, 1.0]}
    relative = {**request, "name": "svc_rel", "reference_frame": "svc_bot",
                "initial_pose": ahead_1m}  # fmt: skip
    base = json.loads(_twin(root, "pose", "svc_bot", "--json"))
    assert _peer(root, "call", "/spawn_entity", json.dumps(relative))["reply"]["success"]
    rel = json.loads(_twin(root, "pose", "svc_rel", "--json"))
    ahead = (base["x"] + math.cos(base["yaw"]), base["y"] + math.sin(base["yaw"]))
    assert (rel["x"], rel["y"]) == pytest.approx(ahead, abs=0.02), "1 m ahead of svc_bot"
    for name in ("svc_rel", "svc_bot"):
        deleted = _peer(root, "call", "/delete_entity", json.dumps({"name": name}))["reply"]
        assert deleted["success"], deleted
    assert _names(root) == initial, "the world after deleting what the services spawned"
    gone = _peer(root, "call", "/delete_entity", json.dumps({"name": "svc_bot"}))["reply"]
    assert not gone["success"] and "svc_bot" in gone["status_message"], gone


def _server_sockets(pid: int) -> list:
    """The sockets of the server and of its child processes (the bridge's publisher)."""
    children = [
        int(c) for task in Path(f"/proc/{pid}/task").iterdir()
        for c in (task / "children").read_text().split()
    ]  # fmt: skip
    return [s for p in (pid, *children) for s in sockets_of(p)]


def test_the_server_binds_no_address_but_loopback(served) -> None:
    """Every internet socket of the server and its publisher process is bound to 127.0.0.1,
    except Cyclone's receive sockets, which Cyclone binds to the wildcard address whatever its
    configuration says: those are UDP sockets on the domain's ports (multicast 7400 + 250·id and
    + 1, on loopback; unicast + 10 + 2·index and + 11) bound to the loopback device, so none can
    receive from or send to another host. None is connected outside 127.0.0.1 (the kernel's
    sock_diag)."""
    _, proc = served
    found = _server_sockets(proc.pid)
    udp = [s for s in found if s.protocol.startswith("udp")]
    assert len(udp) >= 6, f"not two participants' sockets: is the bridge on? {udp}"
    loopback = socket.if_nametoindex("lo")
    domain_ports = range(
        DDS_BASE_PORT + 250 * int(DOMAIN_ID), DDS_BASE_PORT + 250 * (int(DOMAIN_ID) + 1)
    )
    wildcard = [s for s in found if s.local[0] != "127.0.0.1"]
    for s in wildcard:
        receiving = s.protocol == "udp" and s.local[0] == "0.0.0.0" and s.local[1] in domain_ports
        assert receiving, f"{s.protocol} socket bound to {s.local}: not a Cyclone receive socket"
        assert s.device == loopback, f"UDP socket {s.local} not on the loopback device ({s.device})"
    assert len(wildcard) >= 4, f"not two participants' receive sockets: {wildcard}"
    for s in found:
        assert s.remote[0] in ("0.0.0.0", "127.0.0.1"), f"{s.protocol} socket to {s.remote}"
    status = json.loads(_twin(served[0], "ros", "status", "--json"))
    assert status["local_only"] and status["loopback_device"], status


def test_a_widened_interface_leaves_the_sockets_unbound_from_loopback_and_still_meets(
    served,
) -> None:
    """`twin ros start --interface 127.0.0.1` (an explicit interface: multicast on, here on
    loopback, so nothing leaves the machine) is a widened setting: Cyclone's sockets keep the
    wildcard address with no device, and the loopback peer still finds the world through the
    static peer. `twin ros start` without it confines them again."""
    root, proc = served
    _twin(root, "ros", "stop")
    env = {**_env(root), "ROS_STATIC_PEERS": "127.0.0.1"}
    try:
        started = subprocess.run(
            [sys.executable, "-m", "twin_cli", "ros", "start", "--interface", "127.0.0.1",
             "--json", "--world", WORLD],
            env=env, capture_output=True, text=True, timeout=120,
        )  # fmt: skip
        assert started.returncode == 0, started.stderr
        status = json.loads(started.stdout)
        assert not status["local_only"] and not status["loopback_device"], status
        wildcard = [s for s in _server_sockets(proc.pid) if s.local[0] == "0.0.0.0"]
        assert wildcard and all(s.device == 0 for s in wildcard), wildcard
        assert _peer(root, "listen", "1", "bot")["messages"]["/clock"], "no /clock (widened)"
    finally:
        _twin(root, "ros", "stop")
        _twin(root, "ros", "start", "--services")
    loopback = socket.if_nametoindex("lo")
    wildcard = [s for s in _server_sockets(proc.pid) if s.local[0] == "0.0.0.0"]
    assert wildcard and all(s.device == loopback for s in wildcard), wildcard


def _world_pose(frame: str, edges: dict) -> tuple[np.ndarray, np.ndarray]:
    """`frame`'s world position and quaternion (x, y, z, w), composed along tf's parents."""
    position, quat = np.zeros(3), np.array([0.0, 0.0, 0.0, 1.0])
    while frame in edges:
        t = edges[frame]["transform"]
        p = np.array([t["translation"][k] for k in "xyz"])
        q = np.array([t["rotation"][k] for k in "xyzw"])
        position, quat = p + _rotate(q, position), _multiply(q, quat)
        frame = edges[frame]["header"]["frame_id"]
    assert frame == "world", f"tf chain ends at {frame}, not world"
    return position, quat


def _multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    (ax, ay, az, aw), (bx, by, bz, bw) = a, b
    return np.array([
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ])  # fmt: skip


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return _multiply(_multiply(q, np.array([*v, 0.0])), q * np.array([-1, -1, -1, 1]))[:3]


def _same_rotation(a: np.ndarray, b: list) -> bool:
    return abs(abs(float(np.dot(a, np.array(b)))) - 1.0) < POSE_TOL


def _moved(start: dict, end: dict) -> tuple[float, float, float]:
    """Displacement in the start's heading frame [m] and the heading turned [rad]."""
    dx, dy, yaw = end["x"] - start["x"], end["y"] - start["y"], start["yaw"]
    turned = math.remainder(end["yaw"] - yaw, math.tau)
    return (
        dx * math.cos(yaw) + dy * math.sin(yaw),
        -dx * math.sin(yaw) + dy * math.cos(yaw),
        turned,
    )


def test_ros_start_and_stop_on_a_running_world_and_their_errors(served) -> None:
    """`twin ros start` twice, or with a ROS_DOMAIN_ID out of range, says what and how (exit 2,
    no traceback); `twin ros stop` leaves the graph and `start` joins it again (the shell's
    domain), and the peer sees the world again."""
    root, _ = served
    again = subprocess.run(
        [sys.executable, "-m", "twin_cli", "ros", "start", "--world", WORLD],
        env=_env(root), capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert again.returncode == 2 and "twin ros stop" in again.stderr, again.stderr
    assert "Traceback" not in again.stderr
    stopped = json.loads(_twin(root, "ros", "stop", "--json"))
    assert stopped["local_only"] is True and stopped["domain_id"] == int(DOMAIN_ID)
    bad = subprocess.run(
        [sys.executable, "-m", "twin_cli", "ros", "start", "--world", WORLD],
        env={**_env(root), "ROS_DOMAIN_ID": "999"}, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert bad.returncode == 2, bad.stderr
    assert "ROS_DOMAIN_ID=999" in bad.stderr and "0-232" in bad.stderr, bad.stderr
    assert "Traceback" not in bad.stderr
    started = json.loads(_twin(root, "ros", "start", "--json"))
    assert started["domain_id"] == int(DOMAIN_ID) and started["local_only"] is True
    assert started["services"] == [], "entity services are offered only when asked for"
    got = _peer(root, "listen", "1", "bot")
    assert got["messages"]["/clock"], "no /clock after twin ros stop and start"
    _twin(root, "ros", "stop")
    opened = json.loads(_twin(root, "ros", "start", "--services", "--json"))
    assert opened["services"][:3] == ["/spawn_entity", "/delete_entity", "/get_model_list"]
    assert f"/world/{WORLD}/control" in opened["services"], opened


def test_twin_ros_imports_no_physics_and_no_dds(served) -> None:
    """`twin ros` only asks the server: the client loads neither mujoco, numpy nor cyclonedds."""
    root, _ = served
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "twin_cli", "ros", "status", "--world", WORLD],
        env=_env(root), capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-500:]
    names = set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M))
    heavy = {n.split(".")[0] for n in names} & {"mujoco", "numpy", "cyclonedds", "rosbags"}
    assert not heavy, f"twin ros status imported {heavy}"


def test_the_bridge_follows_deletes_and_loads(served) -> None:
    """A deleted base's cmd_vel reader goes; `twin load` moves the bridge to the loaded world
    (the reply says so) and the peer receives its clock and robots again."""
    root, _ = served
    _twin(root, "delete", "twin_bot")
    deadline = time.monotonic() + 10.0
    while "/twin_bot/cmd_vel" in json.loads(_twin(root, "ros", "status", "--json"))["inputs"]:
        assert time.monotonic() < deadline, "twin_bot's cmd_vel reader outlived its entity"
        time.sleep(0.2)
    saved = root / "saved.json"
    _twin(root, "save", str(saved))
    proc = subprocess.run(
        [sys.executable, "-m", "twin_cli", "load", str(saved), "--world", WORLD],
        env=_env(root), capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    got = _peer(root, "listen", "1", "bot")["messages"]
    assert got["/clock"] and got["/bot/joint_states"], "nothing after twin load"
    inputs = json.loads(_twin(root, "ros", "status", "--json"))["inputs"]
    assert "/bot/cmd_vel" in inputs and not [i for i in inputs if "twin_bot" in i], inputs


NAMED_DIFF = DIFF.replace(
    "</plugin>",
    "<ros><namespace>/demo</namespace><remapping>cmd_vel:=cmd_demo</remapping></ros></plugin>",
)
CONTROLLERS_YAML = """controller_manager:
  ros__parameters:
    update_rate: 100
    joint_state_broadcaster:
      type: joint_state_broadcaster/JointStateBroadcaster
    slide_controller:
      type: joint_trajectory_controller/JointTrajectoryController
    spin_speed:
      type: velocity_controllers/JointGroupVelocityController
slide_controller:
  ros__parameters:
    joints: [slide]
    command_interfaces: [position]
spin_speed:
  ros__parameters:
    joints: [spin]
"""


def test_inputs_take_the_names_the_robots_own_plugins_give(served) -> None:
    """A diff drive's `<ros><namespace>/demo` and `<remapping>cmd_vel:=cmd_demo` make its
    input /demo/cmd_demo; gazebo_ros2_control's `<parameters>` YAML (namespace /arm) replaces
    the default controllers by its own: /arm/slide_controller/joint_trajectory and
    /arm/spin_speed/commands. A Twist and a JointTrajectory sent there act."""
    root, _ = served
    base = root / "named_base.urdf"
    base.write_text(dm.two_wheel_base(NAMED_DIFF))
    _twin(root, "spawn", str(base), "--name", "named_bot", "-y", "-4", "--on-ground")
    params = root / "controllers.yaml"
    params.write_text(CONTROLLERS_YAML)
    plugin = (
        '<gazebo><plugin filename="libgazebo_ros2_control.so" name="gazebo_ros2_control">'
        f"<ros><namespace>/arm</namespace></ros><parameters>{params}</parameters></plugin>"
        "</gazebo></robot>"
    )
    rig = root / "named_rig.urdf"
    rig.write_text(CONTROL_RIG.replace("</robot>", plugin))
    _twin(root, "spawn", str(rig), "--name", "named_rig", "-x", "-6")
    wanted = {
        "/demo/cmd_demo",
        "/arm/slide_controller/joint_trajectory",
        "/arm/spin_speed/commands",
    }
    deadline = time.monotonic() + 10.0
    while not wanted <= set(inputs := json.loads(_twin(root, "ros", "status", "--json"))["inputs"]):
        assert time.monotonic() < deadline, f"inputs {inputs}, wanted {wanted}"
        time.sleep(0.2)
    kept = [i for i in inputs if i.startswith("/named_rig/") or i == "/named_bot/cmd_vel"]
    assert not kept, f"default names kept beside the plugins' own: {kept}"
    start = json.loads(_twin(root, "pose", "named_bot", "--json"))
    assert _peer(root, "drive", "/demo/cmd_demo", "0.3", "0.0", "1.5")["matched"] == 1
    end = json.loads(_twin(root, "pose", "named_bot", "--json"))
    ahead, _, _ = _moved(start, end)
    assert ahead > 0.1, f"named_bot moved {ahead} m on /demo/cmd_demo"
    sent = _peer(
        root, "trajectory", "/arm/slide_controller/joint_trajectory", "slide", "0.1", "0.5"
    )
    assert sent["matched"] == 1, "no reader on /arm/slide_controller/joint_trajectory"
    position = _slide_reaches(root, "named_rig", 0.1)
    assert position == pytest.approx(0.1, abs=0.005), f"slide at {position} m"
