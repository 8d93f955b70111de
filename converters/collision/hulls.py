"""Convex hulls of collision meshes: hull, vertex cap, volumes and the convexity measure."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# A part lighter than this is flat or a sliver: MuJoCo refuses to compile a mesh whose volume is
# too small, so such CoACD parts are dropped [m^3] (a 0.1 mm cube).
MIN_PART_VOLUME = 1e-12
# Fewer than 4 distinct points cannot span a volume.
MIN_PART_VERTICES = 4


@dataclass(frozen=True)
class MeshVolumes:
    """Volumes of one mesh: `mesh` is None when the mesh is not closed (volume undefined) [m^3]."""

    mesh: float | None
    hull: float

    @property
    def convexity(self) -> float | None:
        """Mesh volume over hull volume: 1 for a convex solid, small for a cup; None if open."""
        if self.mesh is None or self.hull <= 0.0:
            return None
        return self.mesh / self.hull


def _trimesh(vertices: np.ndarray, faces: np.ndarray):
    import trimesh

    return trimesh.Trimesh(np.asarray(vertices, float), np.asarray(faces, np.int64), process=False)


def volumes(vertices: np.ndarray, faces: np.ndarray) -> MeshVolumes:
    """Volume of a mesh and of its convex hull.

    Args:
        vertices: (N, 3) [m].
        faces: (M, 3) vertex indices.

    Returns:
        Both volumes [m^3]; the mesh volume only when the mesh is watertight (a closed surface),
        because the signed volume of an open surface depends on where it is open.
    """
    mesh = _trimesh(vertices, faces)
    mesh.merge_vertices()
    closed = mesh.is_watertight and mesh.volume > 0.0
    hull = convex_hull(vertices)
    return MeshVolumes(mesh=float(mesh.volume) if closed else None, hull=hull_volume(hull))


def convex_hull(
    vertices: np.ndarray, max_vertices: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The convex hull of a point set, optionally capped to `max_vertices` hull vertices.

    The cap keeps the hull vertices chosen by farthest-point sampling (starting from the vertex
    farthest from the centroid), then takes the hull of those: the capped hull lies inside the
    full hull, so it never makes a part fatter than the source.

    Args:
        vertices: (N, 3) [m].
        max_vertices: cap on hull vertices (>= 4), or None for no cap.

    Returns:
        (vertices (K, 3) [m], faces (F, 3)) of the hull, faces wound outwards.
    """
    import trimesh

    hull = trimesh.convex.convex_hull(np.asarray(vertices, float))
    points = np.asarray(hull.vertices)
    if max_vertices is not None and len(points) > max_vertices:
        keep = farthest_points(points, max(MIN_PART_VERTICES, max_vertices))
        hull = trimesh.convex.convex_hull(points[keep])
    return np.asarray(hull.vertices, float), np.asarray(hull.faces, np.int32)


def farthest_points(points: np.ndarray, count: int) -> np.ndarray:
    """Indices of `count` points picked greedily, each the farthest from those already picked.

    Args:
        points: (N, 3) [m].
        count: how many to keep (<= N).

    Returns:
        (count,) int indices into `points`.
    """
    start = int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))
    chosen = [start]
    dist = np.linalg.norm(points - points[start], axis=1)
    for _ in range(min(count, len(points)) - 1):
        nxt = int(np.argmax(dist))
        chosen.append(nxt)
        dist = np.minimum(dist, np.linalg.norm(points - points[nxt], axis=1))
    return np.asarray(chosen)


def hull_volume(hull: tuple[np.ndarray, np.ndarray]) -> float:
    """Volume of a closed convex part given as (vertices, faces) [m^3]."""
    vertices, faces = hull
    if len(faces) == 0:
        return 0.0
    tri = vertices[faces]
    return float(abs(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum()) / 6.0)


def usable_part(vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether a convex part can become a MuJoCo mesh: enough vertices and a real volume."""
    if len(vertices) < MIN_PART_VERTICES or len(faces) < 4:
        return False
    return hull_volume((np.asarray(vertices, float), np.asarray(faces))) > MIN_PART_VOLUME
