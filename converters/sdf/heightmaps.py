"""SDF `<heightmap>` → a description geometry: the image checked here, so a bad one is refused
with file:line; the builder makes it a MuJoCo height field (`converters.mjcf.heightfields`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from converters.description import Geometry
from converters.resources.height_images import read_height_image
from converters.sdf.document import SdfContext

# What Gazebo renders a terrain with; the height field needs none of it.
RENDERING_ONLY = ("texture", "blend", "use_terrain_paging", "sampling")


def read_heightmap(ctx: SdfContext, shape: Any, subject: str, base_dir: Path) -> Geometry:
    """`<uri>` (an image, brightness = height), `<size>` x y extent and z range [m].

    Raises:
        SDFError: no uri, an unreadable or non-square image, a size that is not positive.
    """
    uri = ctx.text(shape, "uri")
    if not uri:
        raise ctx.error(shape, "has no <uri>", "give the height image, e.g. model://NAME/h.png")
    path = ctx.resolver.resolve(uri, base_dir=base_dir, element=subject)
    try:
        read_height_image(path)
    except (OSError, ValueError) as exc:
        raise ctx.error(
            shape, f"{path} cannot be a height map ({exc})", "give a square PNG of (2^n+1)² pixels"
        ) from exc
    size = ctx.vector(shape, "size", 3, (1.0, 1.0, 1.0))
    if any(v <= 0 for v in size):
        raise ctx.error(shape, f"size {size} has a value ≤ 0", "give positive sizes in metres")
    return Geometry("heightmap", size, Path(path), uri)


def heightmap_offset(ctx: SdfContext, collision: Any) -> np.ndarray:
    """The translation (4×4) of a heightmap's `<pos>`: its centre in the collision frame."""
    shape = collision.find("geometry/heightmap")
    T = np.eye(4)
    if shape is not None:
        T[:3, 3] = ctx.vector(shape, "pos", 3, (0.0, 0.0, 0.0))
    return T
