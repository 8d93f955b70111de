"""Offscreen pictures of a world: one PNG of its scene, rendered with mujoco.Renderer on EGL.

No window and no browser: MuJoCo renders into an offscreen framebuffer through EGL (Mesa's
llvmpipe on a machine without GPU: ~17 frames/s at 320×240 on one core). `MUJOCO_GL` is read
when mujoco is first imported, so a process that renders sets it first (`use_egl`). The camera is
MuJoCo's free camera aimed at an entity (or the whole scene), described by `CameraView` so that
a caller can project points into the picture with its own pinhole maths.
"""

from __future__ import annotations

import io
import os
import sys
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from twin_cli.errors import OffscreenUnavailableError

if TYPE_CHECKING:
    from collections.abc import Iterable

    import mujoco
    import numpy as np

    from twin_cli.world.engine import World

AZIMUTH_DEG = 135.0  # gzclient's default view: from the +x/+y quadrant, looking down
ELEVATION_DEG = -25.0
DISTANCE_FACTOR = 3.0  # camera distance in entity (or scene) extents
MIN_DISTANCE_M = 1.0  # [m]
MAX_SIZE = 4096  # [px] per side


def use_egl() -> None:
    """Selects EGL for MuJoCo's offscreen rendering unless the user chose a backend.

    Call before the process first imports mujoco (MuJoCo reads MUJOCO_GL on import).
    """
    if "mujoco" not in sys.modules:
        os.environ.setdefault("MUJOCO_GL", "egl")


@dataclass(frozen=True)
class CameraView:
    """A free camera: it looks at `lookat` [m] from `distance` [m] along azimuth/elevation [deg];
    `fovy` [deg] is the vertical field of view; `width` × `height` [px] the picture."""

    lookat: tuple[float, float, float]
    distance: float
    azimuth: float
    elevation: float
    fovy: float
    width: int
    height: int

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def aim(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    lookat: Iterable[float],
    extent: float,
    width: int,
    height: int,
) -> CameraView:
    """The camera that frames a thing of size `extent` [m] centred at `lookat`."""
    distance = max(MIN_DISTANCE_M, DISTANCE_FACTOR * extent)
    return CameraView(
        tuple(float(v) for v in lookat),
        distance,
        AZIMUTH_DEG,
        ELEVATION_DEG,
        float(model.vis.global_.fovy),
        width,
        height,
    )


def renderer(model: mujoco.MjModel, width: int, height: int) -> mujoco.Renderer:
    """A `mujoco.Renderer`, or OffscreenUnavailableError naming what to install."""
    import mujoco

    if not (0 < width <= MAX_SIZE and 0 < height <= MAX_SIZE):
        from twin_cli.errors import InvalidRequestError

        raise InvalidRequestError(
            "snapshot size", f"{width}x{height}", f"give 1-{MAX_SIZE} pixels per side"
        )
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    try:
        return mujoco.Renderer(model, height=height, width=width)
    except Exception as exc:  # ImportError, mujoco.FatalError, RuntimeError from EGL
        backend = os.environ.get("MUJOCO_GL", "") or "unset"
        raise OffscreenUnavailableError(f"MUJOCO_GL={backend}: {exc}") from exc


def render(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    view: CameraView,
    scene_renderer: mujoco.Renderer | None = None,
) -> np.ndarray:
    """The picture as an (height, width, 3) uint8 array."""
    import mujoco

    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.lookat[:] = view.lookat
    camera.distance, camera.azimuth, camera.elevation = (
        view.distance,
        view.azimuth,
        view.elevation,
    )
    r = scene_renderer or renderer(model, view.width, view.height)
    try:
        r.update_scene(data, camera=camera)
        return r.render().copy()
    finally:
        if scene_renderer is None:
            r.close()


PNG_SOFTWARE = "twin"
"""The PNG's `Software` text chunk: how a later snapshot to the same path knows the file is
twin's to replace (`is_twin_png`)."""


def png_bytes(pixels: np.ndarray) -> bytes:
    """PNG encoding of an RGB array (matplotlib's writer: already a dependency)."""
    from matplotlib import image

    buffer = io.BytesIO()
    image.imsave(buffer, pixels, format="png", metadata={"Software": PNG_SOFTWARE})
    return buffer.getvalue()


def is_twin_png(head: bytes) -> bool:
    """Whether a file's first bytes are a PNG that twin wrote (its `Software` chunk, which the
    writer puts before the pixels)."""
    return head.startswith(b"\x89PNG\r\n\x1a\n") and b"Software\x00" + PNG_SOFTWARE.encode() in head


def entity_view(
    model: mujoco.MjModel, data: mujoco.MjData, bodies: np.ndarray | None, width: int, height: int
) -> CameraView:
    """The camera on an entity's `bodies` (its root body's centre of mass, its bodies' spread),
    or on the whole scene when `bodies` is None."""
    import numpy as np

    if bodies is None or not len(bodies):
        return aim(model, data, model.stat.center, float(model.stat.extent) / 2, width, height)
    centre = data.xipos[bodies[0]]
    spread = float(np.max(np.linalg.norm(data.xpos[bodies] - centre, axis=1)))
    return aim(model, data, centre, max(spread, 0.3), width, height)


def snapshot_png(
    world: World, *, entity: str | None, width: int, height: int
) -> tuple[bytes, dict]:
    """Renders `world` now; returns the PNG and the camera (`CameraView.to_dict`).

    The state is copied under the world's lock and rendered outside it (the loop keeps
    stepping); the copy is brought up to date with `mj_forward`, since a paused world that was
    just spawned into has not computed its body poses yet.
    """
    import copy

    import mujoco

    with world.lock:
        bodies = None if entity is None else world.index_of(entity).bodies
        model, data = world.model, copy.copy(world.data)
    mujoco.mj_forward(model, data)
    view = entity_view(model, data, bodies, width, height)
    return png_bytes(render(model, data, view)), view.to_dict()
