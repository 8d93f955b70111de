"""Collision-mesh planning: which meshes stay whole, become hulls, or are decomposed (CoACD).

Contract used by the builder (converters/build*.py): it gathers every collision mesh of the robot
into `CollisionRequest`s and calls `prepare_collision_meshes` once, so decomposition can run in
parallel across meshes. Each request gets back a list of convex (or whole) parts to write as mesh
assets, one geom per part. This placeholder returns each mesh whole; the CoACD implementation
(converters/decompose.py) replaces its body without changing the signature.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from converters.report import Report


@dataclass(frozen=True)
class MeshPart:
    """One collision part: vertices [m] (N, 3) float64 in the geom frame, faces (M, 3) int."""

    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class CollisionRequest:
    """A collision mesh of one link, already scaled into metres.

    `key` is unique per request (e.g. "link/collision_index"); `source` is the mesh file path,
    used in messages and in the cache key together with the scale.
    """

    key: str
    link: str
    source: str
    scale: tuple[float, float, float]
    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class CollisionSettings:
    """User choices: `mode` is auto|coacd|hull|mesh; `per_link` overrides it for named links."""

    mode: str = "auto"
    per_link: dict[str, str] = field(default_factory=dict)
    preset: str = "balanced"
    threshold: float | None = None
    max_hulls: int | None = None
    resolution: int | None = None
    seed: int = 0
    jobs: int | None = None
    use_cache: bool = True
    progress: bool = False


def prepare_collision_meshes(
    requests: list[CollisionRequest], settings: CollisionSettings, report: Report
) -> dict[str, list[MeshPart]]:
    """Return the parts for each request key; never raises for a mesh that fails to decompose."""
    return {r.key: [MeshPart(r.vertices, r.faces)] for r in requests}
