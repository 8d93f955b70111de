"""The loaded-mesh value, in its own module so the mesh readers and the mesh store share it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MeshData:
    """A triangle mesh in metres: vertices (N, 3) float64, faces (M, 3) int32.

    `rgba` is the file's own main colour (COLLADA/OBJ/GLB materials; None when it has none) and
    `textured` says whether the file's materials carry an image that twin does not carry.
    """

    vertices: np.ndarray
    faces: np.ndarray
    rgba: tuple[float, float, float, float] | None = None
    textured: bool = False

    @property
    def triangles(self) -> int:
        return len(self.faces)
