"""Skid-steer wheels: as heavy along their rolling direction as the load they carry across it.

A base with several wheels a side slides them sideways in every turn. MuJoCo's solver picks a
sliding contact's force inside the friction cone by the contact's regulariser and by how easily
each direction moves: along the rolling direction the contact spins the light wheel (a 0.3 kg
wheel of radius 0.05 m is 0.16 kg at its rim), across it the contact pushes the base. The force
then leans across, to the heavy side, so the wheels get little traction along their slip.

So each wheel of such a drive gets an armature of m·r², m the robot's mass shared over the drive's
wheels and r the wheel's radius: its rim is then as heavy along its rolling direction as the load
it carries across it. A geared motor reflects an inertia of that order; the URDF states none.
It is a static property of the model, written into the exported MJCF like any joint's. Measured
on a four-wheel base (a/c = 0.4, μ 1) driven open loop at the unicycle's wheel speeds: it turns
at 0.86 of the rate Coulomb friction predicts, ω/(1 + (a/c)²); without the armature at 0.39.
Each wheel is reported.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from converters.gazebo.drive_records import DiffDrive, DriveRecord
from converters.report import Report

if TYPE_CHECKING:
    import mujoco


def skid_wheels(record: DriveRecord) -> tuple[str, ...]:
    """The wheel joints of a drive with several wheels a side, each once (none for others)."""
    if not isinstance(record, DiffDrive):
        return ()
    if len(set(record.left_joints)) < 2 and len(set(record.right_joints)) < 2:
        return ()
    return tuple(dict.fromkeys(record.left_joints + record.right_joints))


def weigh_skid_wheels(
    spec: mujoco.MjSpec, records: tuple[DriveRecord, ...], report: Report
) -> None:
    """Gives each skid-steer wheel its armature (see the module docstring), once even when
    several drives name it. Joints the model lacks are left to the motors' check."""
    mass = _robot_mass(spec)
    done: set[str] = set()
    for record in records:
        wheels = [j for j in skid_wheels(record) if spec.joint(j) is not None]
        if not wheels or not isinstance(record, DiffDrive):
            continue
        load = mass / len(wheels)
        for name in wheels:
            if name in done:
                continue
            done.add(name)
            joint = spec.joint(name)
            radius = _wheel_radius(joint) or record.wheel_diameter / 2.0
            joint.armature = max(float(joint.armature), load * radius**2)
            report.approximated(
                f"joint '{name}'",
                f"<plugin> '{record.name}': skid-steer wheel given an armature of "
                f"{joint.armature:.4g} kg m² (its {load:.4g} kg load at radius {radius:g} m), so "
                "its sliding friction acts along its slip",
                tag="plugin",
            )


def _wheel_radius(joint: mujoco.MjsJoint) -> float:
    """The radius [m] of the wheel's first round collision geom (cylinder, or the ellipsoid a
    drive wheel's cylinder became, or sphere); 0 when it has none."""
    import mujoco

    round_types = (
        mujoco.mjtGeom.mjGEOM_CYLINDER,
        mujoco.mjtGeom.mjGEOM_ELLIPSOID,
        mujoco.mjtGeom.mjGEOM_SPHERE,
    )
    for geom in joint.parent.geoms:
        if (geom.contype or geom.conaffinity) and geom.type in round_types:
            return float(geom.size[0])
    return 0.0


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
