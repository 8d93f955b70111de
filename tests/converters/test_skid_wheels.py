"""Skid-steer wheels as converted: each wheel of a drive with several wheels a side carries the
robot's mass shared over the drive's wheels at its rim as armature (m·r²) and a contact impedance
of at most SKID_IMPEDANCE, reported wheel by wheel; a two-wheeled diff drive's wheels keep what
their tags give. Oracle: the robot's masses and wheel radius written here."""

from __future__ import annotations

from pathlib import Path

import drive_models as dm
import pytest

from converters.gazebo.contact import HARD_IMPEDANCE
from converters.gazebo.skid_wheels import SKID_IMPEDANCE
from converters.pipeline import convert

SKID = (
    '<plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so"><leftFrontJoint>'
    "left_front_joint</leftFrontJoint><rightFrontJoint>right_front_joint</rightFrontJoint>"
    "<leftRearJoint>left_rear_joint</leftRearJoint><rightRearJoint>right_rear_joint"
    "</rightRearJoint><wheelSeparation>0.3</wheelSeparation><wheelDiameter>0.1</wheelDiameter>"
    "</plugin>"
)
DIFF = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter></plugin>"
)
WHEELS = ("left_front_joint", "left_rear_joint", "right_front_joint", "right_rear_joint")
ROBOT_MASS = 6.0 + 4 * 0.3  # drive_models: the chassis and four wheels [kg]


def _compiled(tmp_path: Path, text: str) -> tuple:
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    spec, report = convert(path)
    return spec.compile(), report  # type: ignore[attr-defined]


def test_each_skid_steer_wheel_carries_its_load_at_its_rim_and_a_softer_contact(
    tmp_path: Path,
) -> None:
    model, report = _compiled(tmp_path, dm.skid_steer_bot(SKID))
    for name in WHEELS:
        joint = model.joint(name)
        assert model.dof_armature[joint.dofadr[0]] == pytest.approx(
            ROBOT_MASS / 4 * dm.R**2, rel=1e-9
        )
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == joint.bodyid[0]]
        assert geoms and all(model.geom_solimp[g][0] <= SKID_IMPEDANCE for g in geoms)
    reported = [e for e in report.entries if "skid-steer wheel" in e.detail]
    assert sorted(e.subject for e in reported) == sorted(f"joint '{j}'" for j in WHEELS)


def test_a_two_wheeled_diff_drive_keeps_its_wheels_as_tagged(tmp_path: Path) -> None:
    model, report = _compiled(tmp_path, dm.two_wheel_base(DIFF))
    for name in ("wheel_left_joint", "wheel_right_joint"):
        joint = model.joint(name)
        assert model.dof_armature[joint.dofadr[0]] == 0.0
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == joint.bodyid[0]]
        assert all(model.geom_solimp[g][0] == pytest.approx(HARD_IMPEDANCE) for g in geoms)
    assert not [e for e in report.entries if "skid-steer wheel" in e.detail]
