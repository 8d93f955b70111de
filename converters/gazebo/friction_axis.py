"""`fdir1` along a round geom's axis (a wheel's axle) through a contact-only capsule on that axis.

Gazebo turns `fdir1` into the world with the collision's pose (`ODEPhysics::Collide`), so an
`fdir1` along a wheel's axle stays along the axle as the wheel spins and the base turns: μ1
across the wheel, μ2 along it (t2 = n × t1). MuJoCo builds a plane contact's frame from the
normal alone for every geom type but one: a capsule's contact with a plane has row 1 of its
frame along the capsule's axis (measured at headings 0°, 30° and 90°, wheel angles 0° and 40°).

So a cylinder, a round ellipsoid (a drive wheel, `wheel_contact`) or a capsule whose `fdir1` lies
along its axis gets its ground contact from a capsule on that axis: the capsule itself, or a
contact-only capsule of the same radius (contype = conaffinity = 0: it collides only through
the world's explicit pairs, `friction_pairs`), whose two end spheres touch a plane where the
cylinder's rims do, or at the ellipsoid's mid-plane point (half-length AXIS_HALF_LENGTH). The
pair's friction (μ1, μ2) then puts μ1 along `fdir1`, as Gazebo does. Any other `fdir1` turns
with the link in a way no MuJoCo frame follows (on a spinning wheel, out of the contact plane:
ODE uses it as given, unprojected) and stays isotropic.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco

AXIS_SUFFIX = ":friction_axis"
"""Name of the contact-only capsule: the geom's name and this."""
AXIS_HALF_LENGTH = 1e-4
"""Half-length [m] of the capsule standing for an ellipsoid: its end spheres touch a plane
within 0.2 mm of each other on the mid-plane, where the ellipsoid touches it."""
PARALLEL = 0.999
"""|cos| between `fdir1` and the geom's axis for `fdir1` to count as along it."""
HIDDEN_GROUP = 5
"""Geom group of the capsule: not drawn by default (twin draws visuals 2, collisions 3)."""


def along_axis(geom: mujoco.MjsGeom, fdir1: tuple[float, ...]) -> bool:
    """Whether `fdir1` (in the collision's frame, the geom's) lies along a round geom's axis.

    Args:
        geom: the collision geom; a cylinder, a capsule, or an ellipsoid with equal first two
            semi-axes (its third is the axis).
        fdir1: Gazebo's first friction direction, not necessarily of unit length.
    """
    import mujoco

    kind = int(geom.type)
    size = np.asarray(geom.size, dtype=float)
    round_ellipsoid = kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID and abs(size[0] - size[1]) < 1e-12
    rounds = (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE)
    if not (kind in rounds or round_ellipsoid):
        return False
    direction = np.asarray(fdir1, dtype=float)
    norm = float(np.linalg.norm(direction))
    return norm > 0.0 and abs(float(direction[2])) / norm >= PARALLEL


def axis_capsule(spec: mujoco.MjSpec, geom: mujoco.MjsGeom) -> str:
    """The capsule that carries `geom`'s contacts with the world: `geom` itself if it is a
    capsule, else a new contact-only capsule on its axis (contact settings copied).

    Returns:
        The capsule's name.
    """
    import mujoco

    if int(geom.type) == mujoco.mjtGeom.mjGEOM_CAPSULE:
        return geom.name
    size = np.asarray(geom.size, dtype=float)
    half = size[1] if int(geom.type) == mujoco.mjtGeom.mjGEOM_CYLINDER else AXIS_HALF_LENGTH
    body = geom.parent
    capsule = body.add_geom(
        name=f"{geom.name}{AXIS_SUFFIX}",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        size=[float(size[0]), float(half), 0.0],
        pos=[float(v) for v in geom.pos],
        quat=[float(v) for v in geom.quat],
    )
    capsule.contype, capsule.conaffinity = 0, 0
    capsule.group, capsule.density = HIDDEN_GROUP, 0.0
    capsule.rgba = np.zeros(4, dtype=np.float32)
    capsule.friction, capsule.priority = np.array(geom.friction), int(geom.priority)
    capsule.condim, capsule.solref = int(geom.condim), np.array(geom.solref)
    capsule.solimp = np.array(geom.solimp)
    capsule.margin, capsule.gap = float(geom.margin), float(geom.gap)
    return capsule.name


def stands_for(spec: mujoco.MjSpec, geom: mujoco.MjsGeom) -> mujoco.MjsGeom | None:
    """The geom an axis capsule stands for (None if `geom` is not one)."""
    if not geom.name.endswith(AXIS_SUFFIX):
        return None
    return spec.geom(geom.name.removesuffix(AXIS_SUFFIX))


def centre_axis_capsule(spec: mujoco.MjSpec, geom: mujoco.MjsGeom) -> None:
    """Shortens the axis capsule of a wheel cylinder turned into an ellipsoid (`wheel_contact`),
    so that it touches the ground on the mid-plane as the ellipsoid does."""
    capsule = spec.geom(f"{geom.name}{AXIS_SUFFIX}")
    if capsule is not None:
        size = np.array(capsule.size, dtype=float)
        size[1] = AXIS_HALF_LENGTH
        capsule.size = size
