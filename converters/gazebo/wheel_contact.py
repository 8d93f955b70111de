"""Drive wheels touch the ground on their mid-plane, where the drive's kinematic model puts them.

A collision cylinder lying on a plane touches it at both cap rims: MuJoCo puts a contact on
each rim, as ODE's cylinder-plane collider does. In a turn at ω the two rims of one wheel need
ground speeds ω·width apart, but they spin together, so each rim slips against the other and
the pair resists the turn. Measured on a 0.3 m track base turning at 0.5 rad/s (0.3 m/s):
with 3 cm wide wheels the base turned at 0.42-0.43 rad/s, its rims pushing 10-27 N against each
other, and ended 0.21 m off the unicycle's path over 1.2 m with its encoder odometry 18 cm from
the world pose; with 4 mm wheels it still drifted 1.1 cm. A tyre's contact patch is centred on
its mid-plane and yields across its width, and every drive plugin's `wheel_separation` is
measured between mid-planes: that is the contact the plugin's model expects.

So each collision cylinder of a rolling wheel a drive names, whose axis is the wheel joint's
axis, becomes an ellipsoid with the same radius and width (semi-axes r, r, width/2). It touches a
plane at one point on the mid-plane (the same turn: within 0.5 % of the unicycle's path and
2 mm of odometry), keeps the cylinder's rolling radius, friction and contact parameters, and
differs from it only at the tyre's shoulders. Each change is reported for its wheel.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.gazebo.drive_records import (
    AckermannDrive,
    DiffDrive,
    DriveRecord,
    HolonomicDrive,
    TricycleDrive,
)
from converters.gazebo.friction_axis import centre_axis_capsule
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

PARALLEL = 0.999  # |cos| between the cylinder's and the joint's axes for a rolling wheel


def rolling_joints(record: DriveRecord) -> tuple[str, ...]:
    """The joints of the wheels a drive rolls on the ground (not its steering joints)."""
    if isinstance(record, DiffDrive):
        return record.wheel_joints()
    if isinstance(record, AckermannDrive):
        return record.left_joints + record.right_joints
    if isinstance(record, TricycleDrive):
        return (
            record.actuated_wheel_joint,
            record.encoder_left_joint,
            record.encoder_right_joint,
        )
    if isinstance(record, HolonomicDrive):
        return record.wheel_joints_named
    return ()


def centre_wheel_contacts(
    spec: mujoco.MjSpec, records: tuple[DriveRecord, ...], report: Report
) -> None:
    """Makes each drive wheel's collision cylinders touch the ground on their mid-plane (see the
    module docstring). Joints the model lacks are left to the motors' check."""
    done: set[str] = set()
    for record in records:
        for joint in rolling_joints(record):
            if joint in done or spec.joint(joint) is None:
                continue
            done.add(joint)
            for geom in _wheel_cylinders(spec.joint(joint)):
                radius, half_width = float(geom.size[0]), float(geom.size[1])
                _to_ellipsoid(geom)
                centre_axis_capsule(spec, geom)  # an fdir1 capsule touches where it does
                report.approximated(
                    f"joint '{joint}'",
                    f"<plugin> '{record.name}': wheel cylinder (radius {radius:g} m, width "
                    f"{2 * half_width:g} m) touches the ground on its mid-plane (an ellipsoid "
                    "of the same radius and width), not at both rims",
                    tag="collision",
                )


def _wheel_cylinders(joint: mujoco.MjsJoint) -> list[mujoco.MjsGeom]:
    """The collision cylinders of the joint's body whose axis is the joint's axis."""
    import mujoco

    body = joint.parent
    axis = np.asarray(joint.axis, dtype=float)
    axis = axis / (np.linalg.norm(axis) or 1.0)
    found = []
    for geom in body.geoms:
        colliding = geom.contype or geom.conaffinity
        if geom.type != mujoco.mjtGeom.mjGEOM_CYLINDER or not colliding:
            continue
        rot = np.empty(9)
        mujoco.mju_quat2Mat(rot, np.asarray(geom.quat, dtype=float))
        if abs(float(rot.reshape(3, 3)[:, 2] @ axis)) >= PARALLEL:
            found.append(geom)
    return found


def _to_ellipsoid(geom: mujoco.MjsGeom) -> None:
    import mujoco

    radius, half_width = float(geom.size[0]), float(geom.size[1])
    geom.type = mujoco.mjtGeom.mjGEOM_ELLIPSOID
    geom.size = np.array([radius, radius, half_width])
