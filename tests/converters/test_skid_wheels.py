"""Skid-steer wheels as converted: a drive adds nothing to its wheels' inertia (no armature, no
report line about their weight), with one wheel a side or several, whichever plugins name them.
Their turn comes from the contacts alone (tests/twin_cli/control/test_skid_steer.py). Oracle: the
robot's file, which states no armature."""

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


def _converted(tmp_path: Path, text: str) -> tuple:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    spec, report = convert(path)
    return spec.compile(), report  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    ("robot", "plugins", "wheels"),
    [
        (dm.skid_steer_bot, dm.SKID_STEER_ROS1, WHEELS),
        (dm.skid_steer_bot, dm.SKID_STEER_ROS1 + GZ_PAIRS, WHEELS),
        (dm.two_wheel_base, DIFF, ("wheel_left_joint", "wheel_right_joint")),
    ],
    ids=["ros1_skid_steer", "two_drives_on_the_same_wheels", "two_wheeled_diff_drive"],
)
def test_a_drive_leaves_its_wheels_inertia_as_the_file_gives_it(
    tmp_path: Path, robot, plugins: str, wheels: tuple[str, ...]
) -> None:
    model, report = _converted(tmp_path, robot(plugins))
    for name in wheels:
        assert model.dof_armature[model.joint(name).dofadr[0]] == 0.0, name
    assert not [e for e in report.entries if "armature" in e.detail]
