"""Skid-steer wheels as converted: each wheel of a drive with several wheels a side carries the
robot's mass shared over the drive's wheels at its rim as armature (m·r², r the wheel's own
radius), reported once per wheel; a two-wheeled diff drive's wheels keep none. Oracle: the
robot's masses and wheel radius written here."""

from __future__ import annotations

from pathlib import Path

import drive_models as dm
import pytest

from converters.pipeline import convert

GZ_PAIRS = (  # the same wheels named again by a second drive
    '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive"><left_joint>'
    "left_front_joint</left_joint><left_joint>left_rear_joint</left_joint><right_joint>"
    "right_front_joint</right_joint><right_joint>right_rear_joint</right_joint>"
    "<wheel_separation>0.3</wheel_separation><wheel_radius>0.05</wheel_radius></plugin>"
)
DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter></plugin>"
)
WHEELS = ("left_front_joint", "left_rear_joint", "right_front_joint", "right_rear_joint")
ROBOT_MASS = 6.0 + 4 * 0.3  # drive_models: the chassis and four wheels [kg]


def _converted(tmp_path: Path, text: str) -> tuple:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    spec, report = convert(path)
    return spec.compile(), report  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    "plugins",
    [
        dm.SKID_STEER_ROS1,
        # the plugin's default diameter (0.15 m) is not the wheel's
        dm.SKID_STEER_ROS1.replace("<wheelDiameter>0.1</wheelDiameter>", ""),
        dm.SKID_STEER_ROS1 + GZ_PAIRS,
    ],
)
def test_each_skid_steer_wheel_carries_its_load_at_its_rim(tmp_path: Path, plugins: str) -> None:
    model, report = _converted(tmp_path, dm.skid_steer_bot(plugins))
    for name in WHEELS:
        armature = model.dof_armature[model.joint(name).dofadr[0]]
        assert armature == pytest.approx(ROBOT_MASS / 4 * dm.R**2, rel=1e-9)
    reported = [e.subject for e in report.entries if "skid-steer wheel" in e.detail]
    assert sorted(reported) == sorted(f"joint '{j}'" for j in WHEELS), "once per wheel"


def test_a_two_wheeled_diff_drive_keeps_its_wheels_as_they_are(tmp_path: Path) -> None:
    model, report = _converted(tmp_path, dm.two_wheel_base(DIFF))
    for name in ("wheel_left_joint", "wheel_right_joint"):
        assert model.dof_armature[model.joint(name).dofadr[0]] == 0.0
    assert not [e for e in report.entries if "skid-steer wheel" in e.detail]
