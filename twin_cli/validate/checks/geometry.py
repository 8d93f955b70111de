"""Volumes and solid inertias of MuJoCo geoms, computed from their shapes (an independent oracle).

Used by the plausibility check: a link's declared mass and inertia are compared to those of a
uniform solid filling its collision geometry. Formulas are the textbook solids; meshes use the
convex hull (what MuJoCo collides), measured with trimesh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# MuJoCo geom type codes (mjtGeom), fixed by the MuJoCo ABI.
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = 0, 1, 2, 3, 4, 5, 6, 7


@dataclass(frozen=True)
class Solid:
    """A uniform solid: volume [m³], centroid [m] in its body frame, trace of I/m about it [m²]."""

    volume: float
    centroid: tuple[float, float, float]
    trace_per_mass: float


def geom_solid(model, geom: int) -> Solid | None:
    """The solid of one geom, or None for planes and height fields (no volume).

    Args:
        model: a compiled `mujoco.MjModel`.
        geom: geom id.
    """
    kind = int(model.geom_type[geom])
    size = model.geom_size[geom]
    pos = tuple(float(v) for v in model.geom_pos[geom])
    if kind == MESH:
        return _mesh_solid(model, geom, pos)
    shape = _PRIMITIVES.get(kind)
    if shape is None:
        return None
    volume, trace = shape(size)
    return Solid(volume, pos, trace)


def _sphere(size: np.ndarray) -> tuple[float, float]:
    r = float(size[0])
    return 4.0 / 3.0 * math.pi * r**3, 1.2 * r * r


def _box(size: np.ndarray) -> tuple[float, float]:
    a, b, c = (float(v) for v in size[:3])  # half sizes
    return 8.0 * a * b * c, 2.0 * (a * a + b * b + c * c) / 3.0


def _cylinder(size: np.ndarray) -> tuple[float, float]:
    r, h = float(size[0]), float(size[1])  # radius, half length
    # Izz/m = r²/2, Ixx/m = Iyy/m = (3r² + (2h)²)/12; trace = r² + 2h²/3.
    return math.pi * r * r * 2.0 * h, r * r + 2.0 * h * h / 3.0


def _capsule(size: np.ndarray) -> tuple[float, float]:
    r, h = float(size[0]), float(size[1])
    v_cyl, t_cyl = _cylinder(size)
    v_sph, t_sph = _sphere(size)
    # The two hemispheres' centroids sit h + 3r/8 from the middle (parallel-axis term 2d²).
    t_sph += 2.0 * (h + 3.0 * r / 8.0) ** 2
    return v_cyl + v_sph, (v_cyl * t_cyl + v_sph * t_sph) / (v_cyl + v_sph)


def _ellipsoid(size: np.ndarray) -> tuple[float, float]:
    a, b, c = (float(v) for v in size[:3])
    return 4.0 / 3.0 * math.pi * a * b * c, 2.0 * (a * a + b * b + c * c) / 5.0


_PRIMITIVES = {
    SPHERE: _sphere,
    BOX: _box,
    CYLINDER: _cylinder,
    CAPSULE: _capsule,
    ELLIPSOID: _ellipsoid,
}


def _mesh_solid(model, geom: int, pos: tuple[float, float, float]) -> Solid | None:
    """Convex hull of the geom's mesh: MuJoCo collides a mesh as its hull."""
    import mujoco
    import trimesh

    mesh = int(model.geom_dataid[geom])
    start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    vertices = np.asarray(model.mesh_vert[start : start + count], dtype=float)
    if count < 4:
        return None
    try:
        hull = trimesh.Trimesh(vertices=vertices).convex_hull
    except Exception:  # qhull rejects flat point sets; such a mesh has no volume
        return None
    volume = float(hull.volume)
    if volume <= 0.0:
        return None
    inertia = np.asarray(hull.moment_inertia) / hull.mass  # about the hull's centre of mass
    offset = np.asarray(hull.center_mass)
    # Mesh vertices live in the geom frame; move the centroid into the body frame.
    quat = model.geom_quat[geom]
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, quat)
    centroid = np.asarray(pos) + rot.reshape(3, 3) @ offset
    return Solid(volume, tuple(float(v) for v in centroid), float(np.trace(inertia)))


def body_solid(model, body: int, geoms: list[int]) -> tuple[float, float] | None:
    """Volume [m³] and trace of I/m [m²] about the union's centroid, for a body's geoms.

    Overlaps between geoms are counted twice (a small overestimate for a plausibility bound).
    """
    solids = [s for s in (geom_solid(model, g) for g in geoms) if s is not None]
    volume = sum(s.volume for s in solids)
    if volume <= 0.0:
        return None
    centre = sum(np.asarray(s.centroid) * s.volume for s in solids) / volume
    trace = 0.0
    for s in solids:
        d2 = float(np.sum((np.asarray(s.centroid) - centre) ** 2))
        trace += s.volume * (s.trace_per_mass + 2.0 * d2)  # parallel axis: trace grows by 2d²
    return volume, trace / volume
