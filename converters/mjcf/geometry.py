"""Visual and collision shapes of the description → planned geoms in body frames, meshes loaded."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from converters.description import Geometry, RobotDescription, Visual
from converters.errors import MeshError
from converters.mjcf.lumping import WORLDBODY, BodyPlan
from converters.mjcf.materials import VisualColour, visual_colour
from converters.report import Report
from converters.resources.mesh_data import MeshData
from converters.resources.meshes import MeshCache, mesh_problem

# Half thickness [m] of the box a finite plane becomes on a moving body: MuJoCo allows plane
# geoms in static bodies only, where Gazebo (and sdformat) take them on any link.
PLANE_HALF_THICKNESS = 5e-4
# A Gazebo heightmap's shape name; it becomes a height field after the other geoms, as a report
# entry with this tag says until it is built.
HEIGHTMAP = "heightmap"
HEIGHTMAP_NOTE = "a <heightmap> becomes a height field in a served world (`twin serve`) only"


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
    static = static_bodies(plan)
    for link in robot.links:
        placement = plan.placements[link.name]
        for role, items in (("visual", link.visuals), ("collision", link.collisions)):
            for index, item in enumerate(items):
                if isinstance(item, Visual) and item.missing is not None:
                    continue  # its mesh was not found: reported by `check_references`
                subject = f"link '{link.name}' {role} {index}"
                geom = _shape(item.geometry, link.name, role, subject, cache, report)
                if geom is not None and geom[0] == "plane" and placement.body not in static:
                    geom = _moving_plane(geom, subject, role, report)
                if geom is None:
                    continue
                T = placement.T_body_link @ item.origin
                colour = visual_colour(item.material) if isinstance(item, Visual) else None
                if colour is not None and geom[2] is not None:
                    colour = _mesh_colour(colour, geom[2], subject, report)
                out.append(_assemble(link.name, placement.body, role, index, geom, T, colour))
    return out


def _shape(
    geometry: Geometry | None, link: str, role: str, subject: str, cache: MeshCache, report: Report
) -> tuple | None:
    """`_plan_one`, or None (said) for no shape, a heightmap (`heightfields` builds it) and a
    visual mesh that cannot be read (Gazebo draws nothing for it and simulates on)."""
    if geometry is not None and geometry.shape == HEIGHTMAP:
        report.ignored(subject, HEIGHTMAP_NOTE, HEIGHTMAP)
        return None
    try:
        geom = _plan_one(geometry, link, cache)
    except MeshError as exc:
        if role != "visual":
            raise
        report.warn(subject, f"left out: {exc}")
        return None
    if geom is None:
        report.ignored(subject, "no geometry")
    return geom


def static_bodies(plan: BodyPlan) -> set[str]:
    """Bodies that never move: the world and every body welded to a static one (a floating
    root moves, and so does a body with a joint)."""
    static = {WORLDBODY}
    for node in plan.bodies:  # parents first
        rooted_free = node.name == plan.root_body and plan.floating
        if node.joint is None and node.parent in static and not rooted_free:
            static.add(node.name)
    return static


def _moving_plane(geom: tuple, subject: str, role: str, report: Report) -> tuple | None:
    """A plane on a moving link: a thin box of its size, or (an infinite plane) left out."""
    _, size, mesh, mesh_file, scale = geom
    if size[0] <= 0 or size[1] <= 0:
        say = report.ignored if role == "visual" else report.warn
        say(subject, "an infinite plane on a moving link is left out (MuJoCo planes are static)")
        return None
    if role == "collision":
        report.approximated(subject, "a plane on a moving link collides as a thin box of its size")
    box = (size[0], size[1], PLANE_HALF_THICKNESS)
    return "box", box, mesh, mesh_file, scale


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
