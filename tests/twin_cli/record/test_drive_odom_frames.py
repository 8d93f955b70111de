"""A recording's odometry frame comes from whichever drive the entity has: each drive record
names its `odometry_frame` and `robot_base_frame`, as its plugin's tags (or defaults) say."""

from __future__ import annotations

from pathlib import Path

import drive_models as dm

from twin_cli.record.frames import sources_of
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

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
    assert _sources(tmp_path, dm.ackermann_car(ACKERMANN)).drive == ("odom_car", "base_link")


def test_a_planar_move_base_records_the_plugins_default_frames(tmp_path: Path) -> None:
    assert _sources(tmp_path, dm.planar_base(PLANAR)).drive == ("odom", "base_footprint")


def test_a_base_without_a_drive_has_no_odometry_frame(tmp_path: Path) -> None:
    assert _sources(tmp_path, dm.two_wheel_base("")).drive is None
