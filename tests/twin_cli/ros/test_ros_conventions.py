"""`twin serve --ros` as ROS's own nodes behave, checked by `ros_peer.py` (a peer that shares no
code with twin) over loopback DDS in a domain of this module's own.

- tf2's buffer refuses a frame's second transform at a stamp it holds (TF_REPEATED_DATA), so a
  paused world, whose state is published again every 0.5 s, must send no `/tf` transform twice.
- `/tf_static` is transient local, keep last 1, every static frame in one message (tf2_ros'
  StaticTransformBroadcaster): a reader that joins late gets all of them.
- A cmd_vel topic has one reader type, as its subscriber has (`ros2 topic echo` refuses a topic
  of two types): a gazebo_ros drive plugin's Twist, a diff_drive_controller's TwistStamped
  (`~/cmd_vel`; Jazzy's only input and Humble's default, `use_stamped_vel: true`).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

import pytest
from ros_cli import ros_env, script_json, twin_ok

pytest.importorskip("cyclonedds", reason="cyclonedds is not installed (CI installs it)")
pytestmark = pytest.mark.xdist_group("ros_live")

WORLD = "ros_conventions"
PEER = Path(__file__).with_name("ros_peer.py")
# A domain per test process, 30-69 (ports below Linux's ephemeral range), shifted from
# test_ros_live's so the two modules never share one in a process.
DOMAIN_ID = str(30 + (os.getpid() + 20) % 40)
ENTITIES = ("bot", "bot2", "bot3")
STATIC = ("lidar", "camera")  # each entity's fixed child links
HEARTBEAT_S = 0.5  # [s] wall: a paused world's state is sent again this often
ROBOT = """<robot name="arm">
  <link name="base_link"><inertial><mass value="2"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="lidar"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="camera"><inertial><mass value="0.1"/>
    <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="flap"><inertial><origin xyz="0.1 0 0"/><mass value="0.2"/>
    <inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="lidar_mount" type="fixed"><parent link="base_link"/><child link="lidar"/>
    <origin xyz="0 0 0.1"/></joint>
  <joint name="camera_mount" type="fixed"><parent link="base_link"/><child link="camera"/>
    <origin xyz="0.1 0 0.05" rpy="0 0.3 0"/></joint>
  <joint name="hinge" type="continuous"><parent link="base_link"/><child link="flap"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/><dynamics damping="0.01"/></joint>
</robot>
"""
WHEELS = ("wheel_left_joint", "wheel_right_joint")
CONTROLLED = "".join(
    f'<joint name="{j}"><command_interface name="velocity"/><state_interface name="position"/>'
    "</joint>"
    for j in WHEELS
)
CONTROLLERS = """controller_manager:
  ros__parameters:
    update_rate: 100
    base_controller:
      type: diff_drive_controller/DiffDriveController
base_controller:
  ros__parameters:
    left_wheel_names: ["wheel_left_joint"]
    right_wheel_names: ["wheel_right_joint"]
    wheel_separation: 0.3
    wheel_radius: 0.05
"""
PLUGIN = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter></plugin>"
)


def _env(runtime: Path) -> dict[str, str]:
    return ros_env(runtime, DOMAIN_ID)


def _twin(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, DOMAIN_ID, WORLD, *args)


def _listen(runtime: Path, seconds: float) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, str(PEER), "listen", str(seconds), ENTITIES[0]],
        env=_env(runtime), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip


def _received(peer: subprocess.Popen) -> dict:
    out, err = peer.communicate(timeout=120)
    assert peer.returncode == 0, f"ros_peer listen: {err[-2000:]}"
    return json.loads(out)["messages"]


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A world served with --ros, running in real time, with three arms spawned one by one."""
    root = tmp_path_factory.mktemp("ros_conventions")
    path = root / "arm.urdf"
    path.write_text(ROBOT)
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("ROS_DOMAIN_ID", DOMAIN_ID)
        patch.delenv("ROS_AUTOMATIC_DISCOVERY_RANGE", raising=False)
        with serve_world(root, WORLD, "--ros"):
            for k, name in enumerate(ENTITIES):
                _twin(root, "spawn", str(path), "--name", name, "-y", str(k), "--on-ground")
            for name, robot in _bases(root).items():
                _twin(root, "spawn", str(robot), "--name", name, "-x", "4", "-y", _Y[name])
            yield root


_Y = {"plugin_base": "0", "controller_base": "2"}


def _bases(root: Path) -> dict[str, Path]:
    """A base driven by gazebo_ros' diff drive plugin, and one by a diff_drive_controller."""
    import drive_models as dm

    (root / "ddc.yaml").write_text(CONTROLLERS)
    control = (
        f'<plugin filename="libgazebo_ros2_control.so" name="control"><parameters>'
        f"{root / 'ddc.yaml'}</parameters></plugin>"
    )
    block = (
        '<ros2_control name="sim" type="system"><hardware><plugin>gazebo_ros2_control/'
        f"GazeboSystem</plugin></hardware>{CONTROLLED}</ros2_control>"
    )
    texts = {
        "plugin_base": dm.two_wheel_base(PLUGIN),
        "controller_base": dm.two_wheel_base(control).replace("</robot>", f"{block}</robot>"),
    }
    paths = {}
    for name, text in texts.items():
        paths[name] = root / f"{name}.urdf"
        paths[name].write_text(text)
    return paths


def _stamp(header: dict) -> tuple[int, int]:
    return header["stamp"]["sec"], header["stamp"]["nanosec"]


def test_a_paused_world_sends_no_tf_transform_twice(served) -> None:
    """A listener joins a running world, which is then paused for at least three heartbeats:
    no child frame's transform comes twice with one stamp (tf2's TF_REPEATED_DATA), the paused
    state's /tf still comes once (its stamp is the paused /clock's), and /clock beats on."""
    root = served
    peer = _listen(root, 5.0)
    time.sleep(2.5)  # the peer's start (about 1 s) and 1.5 s of a running world
    _twin(root, "pause")
    try:
        messages = _received(peer)
    finally:
        _twin(root, "resume")
    pairs = Counter(
        (t["child_frame_id"], _stamp(t["header"]))
        for _, message in messages["/tf"]
        for t in message["transforms"]
    )
    repeated = {pair: n for pair, n in pairs.items() if n > 1}
    assert not repeated, f"{len(repeated)} (frame, stamp) pairs sent more than once: {repeated}"
    assert len(messages["/tf"]) >= 20, f"{len(messages['/tf'])} /tf messages while running"
    clocks = [_stamp({"stamp": m["clock"]}) for _, m in messages["/clock"]]
    paused_beats = clocks.count(clocks[-1])
    assert paused_beats >= 2, f"/clock sent the paused time {paused_beats} times: not paused?"
    last = messages["/tf"][-1][1]["transforms"]
    assert {_stamp(t["header"]) for t in last} == {clocks[-1]}, "the paused state's /tf"
    frames = {t["child_frame_id"] for t in last}
    assert {f"{e}/flap" for e in ENTITIES} <= frames, f"moving frames {sorted(frames)}"


def test_a_late_transient_local_reader_gets_every_static_frame(served) -> None:
    """A reader of /tf_static (transient local, keep last 1) that joins after the five spawns
    gets one message naming every entity's fixed frames (12), none twice."""
    root = served
    messages = _received(_listen(root, 1.5))
    static = messages["/tf_static"]
    assert len(static) == 1, f"{len(static)} /tf_static messages to a late reader (keep last 1)"
    children = [t["child_frame_id"] for t in static[0][1]["transforms"]]
    expected = {f"{e}/{link}" for e in ENTITIES for link in STATIC}
    # the bases' fixed casters, and their drives' odometry frames (fixed at the world)
    expected |= {f"{b}/{link}" for b in _Y for link in ("caster_front", "caster_rear", "odom")}
    assert set(children) == expected, f"static frames {sorted(children)}"
    assert len(children) == len(expected), f"a frame twice in /tf_static: {children}"


def _peer(runtime: Path, *args: str) -> dict:
    return script_json(PEER, runtime, DOMAIN_ID, *args)


def _x(runtime: Path, entity: str) -> float:
    return float(json.loads(_twin(runtime, "pose", entity, "--json"))["x"])


@pytest.mark.parametrize(
    ("entity", "topic", "kind", "other"),
    [
        ("plugin_base", "/plugin_base/cmd_vel", "drive", "drive_stamped"),
        ("controller_base", "/controller_base/base_controller/cmd_vel", "drive_stamped", "drive"),
    ],
)
def test_each_cmd_vel_has_one_reader_of_its_subscribers_type(
    served, entity: str, topic: str, kind: str, other: str
) -> None:
    """A writer of the other type matches no reader and leaves the base where it is (within
    1 cm); a writer of the subscriber's type matches one and drives the base 0.2 m/s for 1.5 s
    of a real-time world (more than 0.1 m; its first tenths of a second go to discovery)."""
    root = served
    start = _x(root, entity)
    stray = _peer(root, other, topic, "0.2", "0.0", "1.5")
    assert stray["matched"] == 0, f"a {other} writer on {topic} matched a reader"
    assert abs(_x(root, entity) - start) < 0.01, f"{entity} moved on a {other} message"
    start = _x(root, entity)
    sent = _peer(root, kind, topic, "0.2", "0.0", "1.5")
    assert sent["matched"] == 1, f"no {kind} reader on {topic}"
    moved = _x(root, entity) - start
    assert moved > 0.1, f"{entity} moved {moved:.3f} m on {topic} ({kind})"
