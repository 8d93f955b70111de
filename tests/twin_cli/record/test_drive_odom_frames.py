"""A recording's odometry frame comes from whichever drive the entity has: each drive record
names its `odometry_frame`, as its plugin's tags (or defaults) say, under the entity's frame
prefix; the odometry's child is the root link's frame."""

from __future__ import annotations

from pathlib import Path

import drive_models as dm

from twin_cli.record.frames import sources_of
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

ACKERMANN = (
    '<plugin name="ack" filename="libgazebo_ros_ackermann_drive.so"><front_left_joint>'
    "front_left_joint</front_left_joint><front_right_joint>front_right_joint</front_right_joint>"
    "<rear_left_joint>rear_left_joint</rear_left_joint><rear_right_joint>rear_right_joint"
    "</rear_right_joint><left_steering_joint>left_steering_joint</left_steering_joint>"
    "<right_steering_joint>right_steering_joint</right_steering_joint><odometry_frame>odom_car"
    "</odometry_frame><robot_base_frame>base_link</robot_base_frame></plugin>"
)
PLANAR = '<plugin name="mover" filename="libgazebo_ros_planar_move.so"/>'


def _sources(tmp_path: Path, text: str):  # noqa: ANN202
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="r")
    with world.lock:
        return sources_of(world, "r", "{entity}/", None)


def test_an_ackermann_base_records_its_plugins_odometry_frames(tmp_path: Path) -> None:
    assert _sources(tmp_path, dm.ackermann_car(ACKERMANN)).drive == ("r/odom_car", "")


def test_a_planar_move_base_records_the_plugins_default_frames(tmp_path: Path) -> None:
    assert _sources(tmp_path, dm.planar_base(PLANAR)).drive == ("r/odom", "")


def test_a_base_without_a_drive_has_no_odometry_frame(tmp_path: Path) -> None:
    assert _sources(tmp_path, dm.two_wheel_base("")).drive is None


NAMED_ODOM = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><ros><namespace>/demo</namespace>'
    "<remapping>odom:=odom_demo</remapping></ros><left_joint>wheel_left_joint</left_joint>"
    "<right_joint>wheel_right_joint</right_joint><wheel_separation>0.3</wheel_separation>"
    "<wheel_diameter>0.1</wheel_diameter></plugin>"
)
ROS1_ODOM = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><robotNamespace>/tb</robotNamespace>'
    "<odometryTopic>wheel_odom</odometryTopic><leftJoint>wheel_left_joint</leftJoint>"
    "<rightJoint>wheel_right_joint</rightJoint></plugin>"
)


def test_the_odometry_topic_is_the_one_the_drive_plugin_names(tmp_path: Path) -> None:
    """`<ros><namespace>` and `odom:=` (ROS 2), `robotNamespace` and `odometryTopic` (ROS 1)
    name the topic, in the live topic list and in a recording; a second robot from the same
    file, whose name is taken, keeps `/<entity>/odom`."""
    from record_helpers import read_bag

    from twin_cli.live.catalogue import live_topics
    from twin_cli.record.bag_recording import BagRecording

    for plugin, topic in ((NAMED_ODOM, "/demo/odom_demo"), (ROS1_ODOM, "/tb/wheel_odom")):
        assert _sources(tmp_path, dm.two_wheel_base(plugin)).odom_topic == topic
    path = tmp_path / "robot.urdf"
    path.write_text(dm.two_wheel_base(NAMED_ODOM))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="r")
    world.spawn(SpawnRequest(str(path), on_ground=True), name="r2", pose=Pose(x=2.0))
    listed = {t.name for t in live_topics(world)}
    assert {"/demo/odom_demo", "/r2/odom"} <= listed and "/r/odom" not in listed, listed
    bag_path = tmp_path / "odom.mcap"
    recording = BagRecording(world, bag_path, rate=100.0).start()
    world.step(100)
    assert recording.stop().error is None
    bag = read_bag(bag_path)
    assert len(bag["/demo/odom_demo"]) >= 10 and "/r/odom" not in bag, sorted(bag)
    assert len(bag["/r2/odom"]) == len(bag["/demo/odom_demo"]), "the second robot keeps its own"
