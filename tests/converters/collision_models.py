"""Small mesh factories for the collision tests, built from formulas (no tunable fixtures)."""

from __future__ import annotations

import numpy as np

from converters.collision.plan import CollisionRequest

# Cup: outer radius 50 mm, wall 8 mm, floor 8 mm, rim at 80 mm [m].
CUP_OUTER_R = 0.05
CUP_INNER_R = 0.042
CUP_FLOOR = 0.008
CUP_RIM = 0.08


def cup_mesh(sections: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """A closed cup made by revolving its wall profile about z; (vertices [m], faces)."""
    import trimesh

    profile = np.array(
        [
            [0.0, 0.0],
            [CUP_OUTER_R, 0.0],
            [CUP_OUTER_R, CUP_RIM],
            [CUP_INNER_R, CUP_RIM],
            [CUP_INNER_R, CUP_FLOOR],
            [0.0, CUP_FLOOR],
        ]
    )
    mesh = trimesh.creation.revolve(profile, sections=sections)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def box_mesh(extents: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """A closed box centred at the origin [m]."""
    import trimesh

    mesh = trimesh.creation.box(extents)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def request(key: str, mesh: tuple[np.ndarray, np.ndarray], link: str | None = None):
    """A CollisionRequest for `mesh` on link `link` (default: the key's first segment)."""
    vertices, faces = mesh
    link = link or key.split("/")[0]
    return CollisionRequest(key, link, f"{link}.stl", (1.0, 1.0, 1.0), vertices, faces)


# The concave bin lives where server tests import it too.
from bin_models import BIN_FLOOR, BIN_OUTER, BIN_WALL, bin_mesh, bin_urdf  # noqa: E402, F401
