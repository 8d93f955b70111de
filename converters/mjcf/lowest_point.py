"""How low a robot's collision geometry reaches: the height that rests it on the ground.

A twin World lowers a robot spawned `--on-ground` by this height, and the exported `home`
keyframe stands a floating robot on the floor by the same rule, so both start it alike. Pure
geometry on a compiled model and its positioned data; nothing here changes either.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco


def collision_geoms(model: mujoco.MjModel, geoms: np.ndarray) -> np.ndarray:
    """The geoms among `geoms` that take part in collisions (contype or conaffinity set)."""
    live = (model.geom_contype[geoms] != 0) | (model.geom_conaffinity[geoms] != 0)
    return geoms[live]


def lowest_point(model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray) -> float | None:
    """The lowest world z [m] of the given geoms' surfaces (planes and height fields skipped).

    Args:
        model: the compiled model.
        data: `model`'s data with kinematics computed (`geom_xpos`, `geom_xmat`).
        geoms: geom ids.

    Returns:
        The lowest z [m], or None when no geom has a bounded shape.
    """
    lows = [_geom_low(model, data, int(g)) for g in geoms]
    lows = [z for z in lows if z is not None]
    return min(lows) if lows else None


def _geom_low(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> float | None:
    """Geom `g`'s lowest world z [m]: its centre less its extent along the world's z axis."""
    import mujoco

    kinds = mujoco.mjtGeom
    kind, size = model.geom_type[g], model.geom_size[g]
    z, rot_z = data.geom_xpos[g][2], data.geom_xmat[g].reshape(3, 3)[2]
    if kind == kinds.mjGEOM_SPHERE:
        return z - size[0]
    if kind == kinds.mjGEOM_CAPSULE:
        return z - abs(rot_z[2]) * size[1] - size[0]
    if kind == kinds.mjGEOM_CYLINDER:
        return z - abs(rot_z[2]) * size[1] - size[0] * np.sqrt(max(0.0, 1.0 - rot_z[2] ** 2))
    if kind == kinds.mjGEOM_BOX:
        return z - float(np.abs(rot_z) @ size)
    if kind == kinds.mjGEOM_ELLIPSOID:
        return z - float(np.sqrt(np.sum((rot_z * size) ** 2)))
    if kind == kinds.mjGEOM_MESH:
        mesh = model.geom_dataid[g]
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        return z + float(np.min(model.mesh_vert[start : start + count] @ rot_z))
    return None
