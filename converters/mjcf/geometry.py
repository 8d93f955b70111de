"""Visual and collision shapes of the description → planned geoms in body frames, meshes loaded."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from converters.description import Geometry, RobotDescription, Visual
from converters.mjcf.lumping import BodyPlan
from converters.mjcf.materials import VisualColour, visual_colour
from converters.report import Report
from converters.resources.mesh_data import MeshData
from converters.resources.meshes import MeshCache, mesh_problem


@dataclass(frozen=True)
class GeomPlan:
    """One geom to create.

    Attributes:
        link, body, role, index: provenance (link, MuJoCo body, visual|collision, n-th).
        kind: box | cylinder | sphere | capsule | mesh.
        size: MuJoCo size (half extents, radius, half length) [m]; empty for meshes.
        T_body_geom: pose in the body (4×4).
        colour: visual colour (visuals only).
        mesh: the scaled mesh (meshes only); mesh_file: its resolved file; scale: its scale.
        degenerate: why the mesh cannot collide (None if it can).
    """

    link: str
    body: str
    role: str
    index: int
    kind: str
    size: tuple[float, ...]
    T_body_geom: np.ndarray
    colour: VisualColour | None = None
    mesh: MeshData | None = None
    mesh_file: str | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    degenerate: str | None = None

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds [m] of this geom in its body frame."""
        if self.mesh is not None:
            points = self.mesh.vertices
        else:
            half = _half_extents(self.kind, self.size)
            points = (
                np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
                * half
            )
        world = points @ self.T_body_geom[:3, :3].T + self.T_body_geom[:3, 3]
        return world.min(axis=0), world.max(axis=0)


def _half_extents(kind: str, size: tuple[float, ...]) -> np.ndarray:
    if kind in ("box", "ellipsoid"):
        return np.asarray(size)
    if kind == "plane":
        return np.array([size[0], size[1], 0.0])
    if kind == "sphere":
        return np.full(3, size[0])
    if kind == "capsule":
        return np.array([size[0], size[0], size[1] + size[0]])
    return np.array([size[0], size[0], size[1]])


def plan_geoms(robot: RobotDescription, plan: BodyPlan, report: Report) -> list[GeomPlan]:
    """Every visual and collision geom of every link, placed in its body, meshes loaded."""
    cache = MeshCache()
    out: list[GeomPlan] = []
    for link in robot.links:
        placement = plan.placements[link.name]
        for role, items in (("visual", link.visuals), ("collision", link.collisions)):
            for index, item in enumerate(items):
                T = placement.T_body_link @ item.origin
                colour = visual_colour(item.material) if isinstance(item, Visual) else None
                geom = _plan_one(item.geometry, link.name, cache)
                if geom is None:
                    report.ignored(f"link '{link.name}' {role} {index}", "no geometry")
                    continue
                if colour is not None and geom[2] is not None:
                    colour = _mesh_colour(
                        colour, geom[2], f"link '{link.name}' visual {index}", report
                    )
                out.append(_assemble(link.name, placement.body, role, index, geom, T, colour))
    return out


def _mesh_colour(
    colour: VisualColour, mesh: MeshData, subject: str, report: Report
) -> VisualColour:
    """A visual mesh without a URDF material is drawn in the file's own main colour (as Gazebo
    draws the file's materials); a texture in the file is reported, not carried."""
    if mesh.textured:
        report.approximated(
            subject,
            "the mesh file's texture is not carried; its average "
            "colour is used when the URDF gives no material",
        )
    if colour.material is None and mesh.rgba is not None:
        return VisualColour(mesh.rgba, None, None)
    return colour


def _assemble(
    link: str,
    body: str,
    role: str,
    index: int,
    geom: tuple,
    T: np.ndarray,
    colour: VisualColour | None,
) -> GeomPlan:
    kind, size, mesh, mesh_file, scale = geom
    degenerate = mesh_problem(mesh) if mesh is not None else None
    return GeomPlan(
        link, body, role, index, kind, size, T, colour, mesh, mesh_file, scale, degenerate
    )


def _plan_one(geometry: Geometry | None, link: str, cache: MeshCache) -> tuple | None:
    """(kind, MuJoCo size, mesh, mesh_file, scale) for one shape, or None if empty.

    MuJoCo sizes are halves: box half extents, cylinder/capsule (radius, half length).
    """
    if geometry is None:
        return None
    unit = (1.0, 1.0, 1.0)
    if geometry.shape == "box":
        return "box", tuple(v / 2 for v in geometry.size), None, None, unit
    if geometry.shape in ("cylinder", "capsule"):
        radius, length = geometry.size
        return geometry.shape, (radius, length / 2), None, None, unit
    if geometry.shape == "sphere":
        return "sphere", (geometry.size[0],), None, None, unit
    if geometry.shape == "ellipsoid":
        return "ellipsoid", tuple(geometry.size), None, None, unit
    if geometry.shape == "plane":
        # MuJoCo: half extents for drawing (0 = infinite) and the grid spacing; it collides
        # as an infinite plane either way, as Gazebo's does.
        return "plane", (geometry.size[0] / 2, geometry.size[1] / 2, 1.0), None, None, unit
    if geometry.shape == "mesh" and geometry.mesh is not None:
        mesh = cache.get(geometry.mesh, geometry.scale, link)
        return "mesh", (), mesh, str(geometry.mesh), geometry.scale
    return None
