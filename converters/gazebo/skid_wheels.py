"""Skid-steer wheels: a sliding wheel's friction acts along its slip, as Coulomb's does.

A base with several wheels a side slides them sideways in every turn. MuJoCo's solver picks a
sliding contact's force inside the friction cone by the contact's regulariser and by how easily
each direction moves: along the rolling direction the contact spins the light wheel (a 0.3 kg
wheel of radius 0.05 m is 0.16 kg at its rim), across it the contact pushes the base. With
rigid contacts the force leans across, to the heavy side, so the wheels get little traction
along their slip: a four-wheel base (a/c = 0.4) turned at a third of its commanded rate where
Coulomb friction predicts 0.86 of it, and a Husky-sized base (a/c = 0.92) needed its wheels at
five times the differential Coulomb friction asks for (1.85).

So each wheel of such a drive gets:
  - an armature of m·r², m the robot's mass shared over the drive's wheels and r its radius: the
    wheel's rim is then as heavy along its rolling direction as the load it carries across it
    (a geared motor reflects an inertia of that order; the URDF states none);
  - a contact impedance d of at most SKID_IMPEDANCE (a rigid surface has 0.999): the regulariser
    then weighs as much as the inertia, as a tyre's compliance does. The stiffness is kept, so a
    rigid wheel sinks (1 - d)·g/S: 0.08 mm at the 1 ms step.
Measured with the drive's heading loop (`twin_cli/control/skid_trim.py`), the track multiplier it
needs falls to Coulomb's (Husky-sized base: 2.0-2.1, against 1.85 predicted and 1.75-1.875 that
Husky's users set), and the turns follow the unicycle within 0.2-0.9 % of the path on the test
bases (1.3-8 % before). Each wheel is reported.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.gazebo.drive_records import DiffDrive, DriveRecord
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

SKID_IMPEDANCE = 0.5
"""Largest contact impedance d of a skid-steer wheel's collision geoms."""


def skid_wheels(record: DriveRecord) -> tuple[str, ...]:
    """The wheel joints of a drive with several wheels a side (none for other drives)."""
    if not isinstance(record, DiffDrive):
        return ()
    if len(record.left_joints) < 2 and len(record.right_joints) < 2:
        return ()
    return record.left_joints + record.right_joints


def soften_skid_wheels(
    spec: mujoco.MjSpec, records: tuple[DriveRecord, ...], report: Report
) -> None:
    """Gives each skid-steer wheel its armature and contact impedance (see the module
    docstring). Joints the model lacks are left to the motors' check."""
    mass = _robot_mass(spec)
    for record in records:
        wheels = [j for j in skid_wheels(record) if spec.joint(j) is not None]
        if not wheels or not isinstance(record, DiffDrive):
            continue
        radius = record.wheel_diameter / 2.0
        armature = mass / len(wheels) * radius**2
        for name in wheels:
            joint = spec.joint(name)
            joint.armature = max(float(joint.armature), armature)
            softened = _soften_contacts(joint.parent)
            report.approximated(
                f"joint '{name}'",
                f"<plugin> '{record.name}': skid-steer wheel given an armature of "
                f"{joint.armature:.4g} kg m² (its {mass / len(wheels):.4g} kg load at radius "
                f"{radius:g} m) and contact impedance {SKID_IMPEDANCE:g} on {softened} geom(s), "
                "so its sliding friction acts along its slip",
                tag="plugin",
            )


def _soften_contacts(body: mujoco.MjsBody) -> int:
    count = 0
    for geom in body.geoms:
        if not (geom.contype or geom.conaffinity):
            continue
        solimp = np.array(geom.solimp, dtype=float)
        solimp[0] = min(solimp[0], SKID_IMPEDANCE)
        solimp[1] = min(solimp[1], SKID_IMPEDANCE)
        geom.solimp = solimp
        count += 1
    return count


def _robot_mass(spec: mujoco.MjSpec) -> float:
    """The robot's mass [kg]: its bodies' explicit masses, else the compiled model's."""
    explicit = sum(float(b.mass) for b in spec.bodies)
    if explicit > 0:
        return explicit
    try:
        model = spec.copy().compile()
    except ValueError:  # the core reports uncompilable specs
        return 0.0
    return float(model.body_mass.sum())
