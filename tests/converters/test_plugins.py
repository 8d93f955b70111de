"""Gazebo model plugins: the diff drive's parameters (ROS 1 and ROS 2 names), its wheel motors,
and what the report says of every plugin."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import pytest
from models import two_wheel_bot

from converters.errors import ConversionError
from converters.gazebo.plugins import DiffDrive
from converters.pipeline import convert_full

ROS2 = """<plugin name="dd" filename="libgazebo_ros_diff_drive.so">
  <left_joint>lj</left_joint><right_joint>rj</right_joint><wheel_separation>0.2</wheel_separation>
  <wheel_diameter>0.1</wheel_diameter><max_wheel_torque>3</max_wheel_torque>
  <max_wheel_acceleration>2</max_wheel_acceleration><odometry_source>0</odometry_source>
  <update_rate>50</update_rate></plugin>"""
ROS1 = """<plugin name="dd" filename="libgazebo_ros_diff_drive.so">
  <leftJoint>lj</leftJoint><rightJoint>rj</rightJoint><wheelSeparation>0.2</wheelSeparation>
  <wheelDiameter>0.1</wheelDiameter><wheelTorque>3</wheelTorque>
  <wheelAcceleration>2</wheelAcceleration><odometrySource>encoder</odometrySource>
  <updateRate>50</updateRate></plugin>"""
OTHERS = """<plugin name="imu" filename="libgazebo_ros_imu_sensor.so"/>
  <plugin name="control" filename="libgazebo_ros2_control.so"/>"""


def _convert(tmp_path: Path, plugins: str):  # noqa: ANN202
    text = two_wheel_bot(plugins)
    path = tmp_path / "bot.urdf"
    path.write_text(text)
    return convert_full(path)


@pytest.mark.parametrize("plugin", [ROS2, ROS1], ids=["ros2", "ros1"])
def test_diff_drive_parameters_read_under_both_ros_spellings(tmp_path: Path, plugin: str) -> None:
    done = _convert(tmp_path, plugin)
    expected = DiffDrive(
        "dd", done.plugins[0].where, ("lj",), ("rj",), 0.2, 0.1, 3.0, 2.0, "encoder", 50.0
    )
    # No <ros> block (ROS 2) or commandTopic (ROS 1): cmd_vel under the entity's namespace.
    assert done.plugins == (replace(expected, cmd_vel_topic="cmd_vel"),)


def test_plugin_defaults_are_gazebo_ros_diff_drives(tmp_path: Path) -> None:
    done = _convert(
        tmp_path,
        '<plugin name="dd" filename="libgazebo_ros_diff_drive.so">'
        "<left_joint>lj</left_joint><right_joint>rj</right_joint></plugin>",
    )
    drive = done.plugins[0]
    assert (drive.wheel_separation, drive.wheel_diameter, drive.max_wheel_torque) == (
        0.34,
        0.15,
        5.0,
    )
    assert (drive.max_wheel_acceleration, drive.odometry_source, drive.update_rate) == (
        0.0,
        "world",
        100.0,
    )


def test_wheel_joints_get_motors_limited_to_the_max_wheel_torque(tmp_path: Path) -> None:
    model = _convert(tmp_path, ROS2).spec.compile()
    for joint in ("lj", "rj"):
        motor = model.actuator(joint)
        assert model.actuator_trnid[motor.id][0] == mujoco.mj_name2id(
            model, mujoco.mjtObj.mjOBJ_JOINT, joint
        ), f"{joint}'s motor drives {joint}"
        assert list(model.actuator_ctrlrange[motor.id]) == [-3.0, 3.0], "±max_wheel_torque [N m]"


def test_report_names_each_plugin_run_or_not_run(tmp_path: Path) -> None:
    entries = [
        e
        for e in _convert(tmp_path, ROS2 + OTHERS).report.to_dict()["entries"]
        if e["tag"] == "plugin"
    ]
    outcome = {e["detail"].split("'")[1]: (e["outcome"], e["detail"]) for e in entries}
    assert outcome["dd"][0] == "mapped" and "twin drive" in outcome["dd"][1]
    assert outcome["imu"] == (
        "ignored",
        "<plugin> 'imu' libgazebo_ros_imu_sensor.so: not run by twin",
    )
    assert outcome["control"][0] == "mapped" and "command interfaces" in outcome["control"][1]


@pytest.mark.parametrize(
    ("swap", "needle"),
    [
        (("<wheel_separation>0.2<", "<wheel_separation>wide<"), "wheel_separation"),
        (("<odometry_source>0<", "<odometry_source>gps<"), "odometry_source"),
        (("<left_joint>lj<", "<left_joint>nope<"), "nope"),
        (("<wheel_diameter>0.1<", "<wheel_diameter>-1<"), "wheel_diameter"),
    ],
)
def test_bad_plugin_values_name_the_tag(tmp_path: Path, swap: tuple[str, str], needle: str) -> None:
    with pytest.raises(ConversionError, match=needle):
        _convert(tmp_path, ROS2.replace(*swap))
