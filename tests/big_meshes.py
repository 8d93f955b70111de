"""Large generated meshes for the tests of bounded conversions and their progress."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def write_grid_obj(path: Path, faces: int) -> None:
    """A bumpy square of about `faces` triangles as OBJ text, with random heights so that no
    earlier run's mesh store holds it."""
    side = int(np.sqrt(faces / 2)) + 1
    x, y = np.meshgrid(np.linspace(0, 1, side), np.linspace(0, 1, side))
    z = np.random.default_rng().random(x.shape) * 0.01
    index = np.arange(side * side).reshape(side, side) + 1
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([b, d, c], 1)])
    with path.open("w") as stream:
        np.savetxt(stream, np.stack([x.ravel(), y.ravel(), z.ravel()], 1), "v %.6f %.6f %.6f")
        np.savetxt(stream, triangles, "f %d %d %d")
