"""A recording as RViz, Nav2 and robot_state_publisher read it: frames, tf tree, mimics, odom.

The bag is read back with rosbags (record_helpers) and each entity's URDF, taken from its own
`robot_description` in the bag, with ElementTree; nothing of twin's code reads either.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus, package_paths
from models import mimic_pincer, two_wheel_bot, write_urdf
from record_helpers import read_bag, seconds, tf_edges, tree_frames, urdf_joints
from scipy.spatial.transform import Rotation
from sensor_models import bumper_ball, imu_box, lidar_post

from twin_cli.record import BagRecording
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

DRIVE = """<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>lj</left_joint>
<right_joint>rj</right_joint><odometry_frame>odo</odometry_frame>
<robot_base_frame>base</robot_base_frame></plugin>"""
STEPS = 300  # [ms] recorded at 100 Hz
INERTIAL = """<inertial><mass value="0.5"/><inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0"
  ixz="0" iyz="0"/></inertial>"""
# A wheel on a deck that the converter lumps into the chassis (a fixed joint): the wheel's tf
# parent is the deck, a frame inside the chassis body.
CART = f"""<robot name="cart"><link name="chassis">{INERTIAL}</link>
<link name="deck">{INERTIAL}</link><link name="wheel">{INERTIAL}</link>
<joint name="deck_joint" type="fixed"><parent link="chassis"/><child link="deck"/>
  <origin xyz="0.1 0 0.2" rpy="0.3 0 0"/></joint>
<joint name="axle" type="continuous"><parent link="deck"/><child link="wheel"/>
  <origin xyz="0 0.1 0.05" rpy="0 0 0.5"/><axis xyz="0 1 0"/></joint></robot>"""
# rmw's QoS enum values (rmw/types.h) and the names rosbag2 >= Jazzy writes for them
NUMBERS = {
    "history": {"keep_last": 1},
    "reliability": {"reliable": 1, "best_effort": 2},
    "durability": {"transient_local": 1, "volatile": 2},
    "liveliness": {"automatic": 1},
}


def _record(world: World, path: Path, **options: object) -> dict:
    recording = BagRecording(world, path, **options).start()
    for _ in range(STEPS // 10):
        world.step(10)
    assert recording.stop().error is None
    return read_bag(path)


@pytest.fixture(scope="module")
def bag(tmp_path_factory) -> dict:
    """A mimic pincer welded by a `world` link, a two-wheel diff drive whose plugin names its
    frames, an IMU, a lidar on a lumped link and a bumper: 0.3 s at 100 Hz, default prefix."""
    d = tmp_path_factory.mktemp("ros")
    world = World()
    world.spawn(write_urdf(d, mimic_pincer(), "pincer.urdf"), name="p")
    world.spawn(write_urdf(d, two_wheel_bot(DRIVE), "bot.urdf"), name="b", pose=Pose(x=2, z=1))
    imu = imu_box(rate=100.0, yaw=0.3)
    world.spawn(write_urdf(d, imu, "imu.urdf"), name="imu", pose=Pose(y=2, z=0.3))
    world.spawn(write_urdf(d, lidar_post(rate=10.0, samples=31), "l.urdf"), name="lidar")
    world.spawn(write_urdf(d, bumper_ball(), "ball.urdf"), name="ball", pose=Pose(x=1, z=0.1))
    world.spawn(write_urdf(d, CART, "cart.urdf"), name="c", pose=Pose(y=-2, z=1))
    assert "c/deck" not in [world.model.body(b).name for b in range(world.model.nbody)]
    world.data.qvel[world.model.joint("c/axle").dofadr[0]] = 3.0  # [rad/s]: it turns
    return _record(world, d / "ros.mcap")


def _check_frames(bag: dict) -> set[str]:
    """Every header's frame_id (and odometry's child frame) is a frame of the recorded tf tree,
    which is one tree under `world`; returns the frames messages name."""
    frames, named = tree_frames(tf_edges(bag)), set()
    for topic, messages in bag.items():
        for _, m in messages:
            header = getattr(m, "header", None)
            if header is None or (topic.endswith("/joint_states") and header.frame_id == ""):
                continue
            named |= {header.frame_id, getattr(m, "child_frame_id", header.frame_id)}
            for t in getattr(m, "transforms", ()):
                named.add(t.header.frame_id)
    assert named <= frames, f"frames named but not in tf: {sorted(named - frames)}"
    return named


def _check_urdf_parents(bag: dict, prefix: str = "{entity}/") -> None:
    """Each URDF joint is a tf edge from its parent link to its child link: fixed ones on
    /tf_static with the joint's origin, the others on /tf; every link is a frame."""
    edges = tf_edges(bag)
    for topic, messages in bag.items():
        if not topic.endswith("/robot_description"):
            continue
        ((_, description),) = messages
        entity = topic.split("/")[1]
        name = prefix.replace("{entity}", entity)
        for j in urdf_joints(description.data):
            parent, static = edges[name + j["child"]]
            assert parent == name + j["parent"], f"{j['name']}: parent {parent}"
            assert static == (j["type"] == "fixed"), f"{j['name']} on /tf_static: {static}"
        for _, message in bag["/tf_static"][:1]:
            _check_origins(message, urdf_joints(description.data), name)


def _check_origins(message: object, joints: list[dict], name: str) -> None:
    fixed = {name + j["child"]: j for j in joints if j["type"] == "fixed"}
    for t in message.transforms:
        if t.child_frame_id not in fixed:
            continue
        j, v, r = fixed[t.child_frame_id], t.transform.translation, t.transform.rotation
        assert np.allclose([v.x, v.y, v.z], j["xyz"], atol=1e-9), j["name"]
        want = Rotation.from_euler("xyz", j["rpy"]).as_quat()  # x, y, z, w; URDF's fixed axes
        got = np.array([r.x, r.y, r.z, r.w])
        assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-9, j["name"]


def test_every_frame_id_is_a_frame_of_the_recorded_tf_tree(bag):
    named = _check_frames(bag)
    edges = tf_edges(bag)
    assert not [f for f in edges if "sensor:" in f], "sensor sites are frames only if named"
    assert bag["/imu/imu"][0][1].header.frame_id == "imu/imu_link", "the IMU's link"
    assert bag["/lidar/scan"][0][1].header.frame_id == "lidar/scan", "the lidar's lumped link"
    assert edges["lidar/scan"] == ("lidar/base", True)
    assert {m.header.frame_id for _, m in bag["/ball/ball_bumper"]} == {"world"}, "contacts"
    assert "world" in named


def test_tf_parents_are_the_urdf_parents_fixed_joints_static_moving_ones_live(bag):
    _check_urdf_parents(bag)
    edges = tf_edges(bag)
    assert edges["p/world"] == ("world", True), "the pincer's world link is a frame"
    ((_, static),) = bag["/tf_static"]
    (anchor,) = [t for t in static.transforms if t.child_frame_id == "p/world"]
    assert anchor.transform.translation.z == pytest.approx(0.0, abs=1e-12), "welded at z = 0"


def test_a_joint_under_a_lumped_link_turns_about_its_axis_at_its_origin(bag):
    """tf `c/deck → c/wheel` is the axle's origin, then its turn by the recorded position."""
    origin = Rotation.from_euler("xyz", [0, 0, 0.5])
    angles = []
    for (_, js), (_, tf) in zip(bag["/c/joint_states"], bag["/tf"], strict=True):
        (t,) = [t for t in tf.transforms if t.child_frame_id == "c/wheel"]
        assert t.header.frame_id == "c/deck"
        v, r = t.transform.translation, t.transform.rotation
        assert np.allclose([v.x, v.y, v.z], [0, 0.1, 0.05], atol=1e-9)
        want = (origin * Rotation.from_rotvec([0, js.position[0], 0])).as_quat()
        got = np.array([r.x, r.y, r.z, r.w])
        assert min(np.abs(got - want).max(), np.abs(got + want).max()) < 1e-9
        angles.append(js.position[0])
    assert np.ptp(angles) > 0.1, "the wheel turned"


def test_mimic_followers_are_offset_plus_multiplier_times_leader(bag):
    ((_, description),) = bag["/p/robot_description"]
    ((follower, (leader, multiplier, offset)),) = [
        (j["name"], j["mimic"]) for j in urdf_joints(description.data) if j["mimic"]
    ]
    leads = []
    for (_, js), (_, tf) in zip(bag["/p/joint_states"], bag["/tf"], strict=True):
        position = dict(zip(js.name, js.position, strict=True))
        want = offset + multiplier * position[leader]
        assert abs(position[follower] - want) < 1e-9, f"{follower} at {seconds(js.header.stamp)}"
        (t,) = [t for t in tf.transforms if t.child_frame_id == "p/b"]  # the follower's link
        angle = 2.0 * math.atan2(t.transform.rotation.y, t.transform.rotation.w)
        assert abs(angle - want) < 1e-9, "tf turns the follower's link by the same angle"
        leads.append(position[leader])
    assert np.ptp(leads) > 1e-3, "the leader moved"


def test_a_diff_drive_base_hangs_from_its_plugins_odometry_frame(bag):
    edges = tf_edges(bag)
    assert edges["b/odo"] == ("world", True) and edges["b/base"] == ("b/odo", False)
    for (_, odom), (_, tf) in zip(bag["/b/odom"], bag["/tf"], strict=True):
        assert (odom.header.frame_id, odom.child_frame_id) == ("b/odo", "b/base")
        (t,) = [t for t in tf.transforms if t.child_frame_id == "b/base"]
        p, v = odom.pose.pose.position, t.transform.translation
        assert (p.x, p.y, p.z) == (v.x, v.y, v.z), "odometry and tf agree"


@pytest.fixture(scope="module")
def posed(tmp_path_factory) -> Path:
    """An IMU 0.1 m off its link's origin (SDF `<pose>`), recorded for 0.3 s."""
    d = tmp_path_factory.mktemp("posed")
    text = imu_box(rate=100.0).replace("<update_rate>", "<pose>0.1 0 0 0 0 0</pose><update_rate>")
    world = World()
    world.spawn(write_urdf(d, text, "imu.urdf"), name="imu")
    _record(world, d / "posed.mcap")
    return d / "posed.mcap"


def test_a_sensor_off_its_links_origin_names_its_own_frame_fixed_to_the_link(posed):
    bag = read_bag(posed)
    _check_frames(bag)
    assert bag["/imu/imu"][0][1].header.frame_id == "imu/sensor:imu"
    ((_, static),) = bag["/tf_static"]
    (t,) = [t for t in static.transforms if t.child_frame_id == "imu/sensor:imu"]
    assert t.header.frame_id == "imu/imu_link" and t.transform.translation.x == pytest.approx(0.1)


def test_qos_profiles_are_numbers_on_channels_and_names_in_the_metadata(posed):
    """Channels: rmw's enum numbers (rosbag2 before Jazzy converts each policy with `as<int>`;
    Jazzy tries numbers first). The `rosbag2` record (metadata version 9, read by Jazzy only):
    names. Both say the same, and both are the live writers' QoS: latched topics reliable,
    transient local, depth 1; the IMU best effort, depth 5 (SensorDataQoS); the rest reliable,
    depth 10."""
    from mcap.reader import make_reader

    with posed.open("rb") as stream:
        reader = make_reader(stream)
        channels = reader.get_summary().channels.values()
        (meta,) = [m for m in reader.iter_metadata() if m.name == "rosbag2"]
    info = yaml.safe_load(meta.metadata["serialized_metadata"])
    assert info["version"] == 9
    named = {
        t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
        for t in info["topics_with_message_count"]
    }
    latched = {"/tf_static", "/imu/robot_description"}
    assert "/imu/imu" in named, f"no IMU topic in {sorted(named)}"
    for channel in channels:
        (numbers,) = yaml.safe_load(channel.metadata["offered_qos_profiles"])
        (names,) = named[channel.topic]
        for policy, table in NUMBERS.items():
            assert type(numbers[policy]) is int, f"{channel.topic} {policy}: {numbers[policy]}"
            assert table[names[policy]] == numbers[policy], f"{channel.topic} {policy}"
        durability = "transient_local" if channel.topic in latched else "volatile"
        assert names["durability"] == durability and numbers["depth"] == names["depth"]
        sensor = channel.topic == "/imu/imu"
        reliability = "best_effort" if sensor else "reliable"
        depth = 1 if channel.topic in latched else 5 if sensor else 10
        assert (names["reliability"], names["depth"]) == (reliability, depth), channel.topic
        assert type(numbers["deadline"]["sec"]) is int and numbers["deadline"]["sec"] > 0


@needs_corpus
def test_turtlebot3_records_odom_to_base_footprint_and_its_sensor_links(tmp_path):
    robot = CORPUS["turtlebot3_burger"]
    world = World()
    request = SpawnRequest(
        PACKAGES_ROOT / robot["entry"], package_paths=package_paths(robot), on_ground=True
    )
    world.spawn(request, name="tb3")
    bag = _record(world, tmp_path / "tb3.mcap", frame_prefix="")
    _check_frames(bag)
    _check_urdf_parents(bag, prefix="")
    edges = tf_edges(bag)
    assert edges["base_footprint"] == ("odom", False) and edges["odom"] == ("world", True)
    assert edges["wheel_left_link"] == ("base_link", False), "the URDF parent"
    odom = bag["/tb3/odom"][0][1]
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    assert bag["/tb3/scan"][0][1].header.frame_id == "base_scan"
    assert bag["/tb3/imu"][0][1].header.frame_id == "imu_link"
    assert not [f for f in edges if "sensor:" in f]


def test_the_plugins_frames_are_read_in_both_spellings_with_its_defaults(monkeypatch):
    from twin_cli.record.frames import drive_frames, prefix_template

    ros1 = two_wheel_bot(
        '<plugin name="d" filename="libgazebo_ros_diff_drive.so"><leftJoint>lj</leftJoint>'
        "<rightJoint>rj</rightJoint><odometryFrame>odom_a</odometryFrame>"
        "<robotBaseFrame>base</robotBaseFrame></plugin>"
    )
    assert drive_frames(ros1) == ("odom_a", "base")
    assert drive_frames(two_wheel_bot(DRIVE)) == ("odo", "base")
    assert drive_frames(two_wheel_bot("")) == ("odom", "base_footprint"), "the plugin's defaults"
    monkeypatch.setenv("TWIN_FRAME_PREFIX", "")
    assert prefix_template() == "" and prefix_template("r_{entity}/") == "r_{entity}/"
    monkeypatch.delenv("TWIN_FRAME_PREFIX")
    assert prefix_template() == "{entity}/"
