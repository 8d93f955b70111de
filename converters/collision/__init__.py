"""Collision meshes: which stay whole, become convex hulls, or are decomposed by CoACD.

`plan` holds the settings and the per-mesh rule, `prepare` carries the plan out (cache, hulls,
CoACD jobs, fallbacks), `decompose` and `worker` run CoACD in CPU-budgeted processes, `hulls`
computes hulls and volumes, `cache` stores results on disk, `progress` shows them.
"""

from __future__ import annotations

from converters.collision.plan import (
    PRESETS,
    CollisionMode,
    CollisionRequest,
    CollisionSettings,
    MeshPart,
)
from converters.collision.prepare import prepare_collision_meshes

__all__ = [
    "PRESETS",
    "CollisionMode",
    "CollisionRequest",
    "CollisionSettings",
    "MeshPart",
    "prepare_collision_meshes",
]
