"""Gazebo `<heightmap>` collisions → MuJoCo height fields, on the bodies the builder made.

Gazebo's rule (gz-common ImageHeightmap, the terrain both Gazebos build): a pixel's height is
its value / the brightest pixel's value × the z size, the image's top row lies at +y, the
terrain spans the x and y size around its centre. MuJoCo's height field takes half extents in
x and y, an elevation range and a base thickness below it, and scales its data to [0, 1]
itself; so the data goes in as the heights above the lowest one, and the geom is raised by it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from converters.description import Collision, RobotDescription
from converters.errors import InputFileError
from converters.isolated.replay import read_once
from converters.mjcf.builder import COLLISION_CLASS, pose
from converters.mjcf.fixed_base import weld_base
from converters.mjcf.geometry import HEIGHTMAP, static_bodies
from converters.mjcf.lumping import WORLDBODY, LinkPlacement, plan_bodies
from converters.report import Report
from converters.resources.height_images import read_height_image

if TYPE_CHECKING:
    import mujoco

# Thickness [m] MuJoCo gives the height field below its lowest point (it must be positive).
BASE_THICKNESS = 0.5
# Elevation range [m] of a flat height field (MuJoCo needs a positive one).
FLAT_RANGE = 1e-3


def add_height_fields(
    spec: mujoco.MjSpec,
    robot: RobotDescription,
    report: Report,
    *,
    keep_fixed: bool = False,
    fixed_base: bool = False,
) -> int:
    """Add a height field geom for every heightmap collision of `robot` (a built spec of it);
    returns how many. Ones already in the spec are kept as they are. `keep_fixed` and
    `fixed_base` are the build's options: the body plan must be the builder's, so that a
    heightmap on a root welded by `--fixed-base` counts as static."""
    found = _heightmaps(robot, keep_fixed, fixed_base)
    if not found:
        return 0
    report.entries[:] = [e for e in report.entries if e.tag != HEIGHTMAP]
    added = 0
    for link, index, collision, placement in found:
        subject = f"link '{link}' collision {index}"
        if placement is None:
            report.warn(subject, "a heightmap on a moving link is left out (MuJoCo's are static)")
        elif spec.geom(f"{link}_collision_{index}") is None:
            _add_one(spec, f"{link}_collision_{index}", placement, collision, report, subject)
            added += 1
    return added


def read_height_images(
    robot: RobotDescription, *, keep_fixed: bool = False, fixed_base: bool = False
) -> None:
    """Read the images `add_height_fields` reads (a served conversion's reading stage).

    Raises:
        InputFileError: an image that cannot be a height map.
    """
    for _, _, collision, placement in _heightmaps(robot, keep_fixed, fixed_base):
        if placement is not None:
            assert collision.geometry is not None and collision.geometry.mesh is not None
            _heights(collision.geometry.mesh, collision.geometry.size[2])


def _heightmaps(
    robot: RobotDescription, keep_fixed: bool, fixed_base: bool
) -> list[tuple[str, int, Collision, LinkPlacement | None]]:
    """(link, index, collision, placement: None on a moving body) of each heightmap."""
    found = [
        (link.name, index, c)
        for link in robot.links
        for index, c in enumerate(link.collisions)
        if c.geometry is not None and c.geometry.shape == HEIGHTMAP
    ]
    if not found:
        return []
    plan = plan_bodies(
        robot,
        preserved=robot.gazebo.preserved_joints,
        keep_fixed=keep_fixed,
        static=robot.gazebo.static,
    )
    if fixed_base:  # reported once already, by the builder
        plan = weld_base(plan, Report())
    static = static_bodies(plan)
    out = []
    for link, index, collision in found:
        placement = plan.placements[link]
        out.append((link, index, collision, placement if placement.body in static else None))
    return out


def _add_one(
    spec: mujoco.MjSpec,
    name: str,
    placement: LinkPlacement,
    collision: Collision,
    report: Report,
    subject: str,
) -> None:
    import mujoco

    geometry = collision.geometry
    assert geometry is not None and geometry.mesh is not None  # a heightmap's image
    heights = _heights(geometry.mesh, geometry.size[2])
    low, high = float(heights.min()), float(heights.max())
    span = high - low
    data = (heights - low) / span if span > 0 else np.zeros_like(heights)
    rows, cols = data.shape
    x, y = geometry.size[0] / 2, geometry.size[1] / 2
    spec.add_hfield(
        name=name,
        size=[x, y, span if span > 0 else FLAT_RANGE, BASE_THICKNESS],
        nrow=rows,
        ncol=cols,
        userdata=data.reshape(-1).tolist(),
    )
    raised = np.eye(4)
    raised[2, 3] = low
    T = placement.T_body_link @ collision.origin @ raised
    body = spec.worldbody if placement.body == WORLDBODY else spec.body(placement.body)
    position, quat = pose(T)
    geom = body.add_geom(spec.find_default(COLLISION_CLASS), name=name, pos=position, quat=quat)
    geom.type = mujoco.mjtGeom.mjGEOM_HFIELD
    geom.hfieldname = name
    report.mapped(
        subject,
        f"heightmap {geometry.uri}: a {rows}×{cols} height field, "
        f"{geometry.size[0]:g} × {geometry.size[1]:g} m, heights {low:.4g} to {high:.4g} m",
    )


def _heights(path: Path, z_size: float) -> np.ndarray:
    """Heights [m] on MuJoCo's grid: row 0 at -y (the image's bottom row), column 0 at -x."""
    try:
        brightness = read_once("height image", (str(path),), lambda: read_height_image(path))
    except (OSError, ValueError) as exc:
        raise InputFileError(str(path), f"cannot be a height map ({exc})", "fix the image") from exc
    peak = float(brightness.max())
    heights = brightness / peak * z_size if peak > 0 else np.zeros_like(brightness)
    return heights[::-1]
