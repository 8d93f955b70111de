"""Camera and depth camera: offscreen rendering of the sensor's MuJoCo camera, where GL exists.

The converter gives each camera sensor a MuJoCo camera `sensor:<name>` looking along the
sensor's +x (Gazebo's convention) with the vertical field of view of its horizontal one and
aspect. Rendering needs an offscreen OpenGL context, which MuJoCo picks when it is first
imported (`MUJOCO_GL=egl` or `osmesa`; measured: EGL on Mesa llvmpipe ~17 frames/s at
320×240). Without one, reading the camera fails with a message saying how to get one; the
other sensors keep working. Depth images are metres along the view axis (32FC1).
"""

from __future__ import annotations

import threading
from typing import Any

import mujoco
import numpy as np

from converters.description.sensors import CameraSpec
from twin_cli.errors import InvalidRequestError
from twin_cli.sensors.frames import element_id
from twin_cli.sensors.readings import ImageReading


class CameraSensor:
    """One camera (`camera`, `depth`, `rgbd_camera`, ...) of an entity."""

    def __init__(self, spec: CameraSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.camera = -1
        self._renderer: Any = None
        self._lock = threading.Lock()  # one GL context: one render at a time

    def bind(self, model: Any) -> None:
        name = f"{self.entity}/{self.spec.site}"
        self.camera = element_id(model, mujoco.mjtObj.mjOBJ_CAMERA, "camera", name, self.entity)
        self._close()

    def read(self, model: Any, data: Any, time: float) -> ImageReading:
        """Raises: InvalidRequestError: no offscreen GL here, or the image is too large."""
        with self._lock:
            renderer = self._open(model)
            renderer.update_scene(data, camera=self.camera)
            pixels = renderer.render()
        encoding = "32FC1" if self.spec.depth else "rgb8"
        raw = pixels.astype(np.float32 if self.spec.depth else np.uint8).tobytes()
        return ImageReading(
            self.spec.name, self.spec.type, time, self.spec.frame_id,
            self.spec.width, self.spec.height, encoding, raw,
        )  # fmt: skip

    def _open(self, model: Any) -> Any:
        if self._renderer is not None:
            self._renderer._gl_context.make_current()  # requests run on pool threads
            return self._renderer
        try:
            renderer = mujoco.Renderer(model, self.spec.height, self.spec.width)
        except (mujoco.FatalError, RuntimeError, ValueError) as exc:
            raise InvalidRequestError(
                f"camera sensor '{self.spec.name}' of [{self.entity}]",
                f"cannot render offscreen ({str(exc).splitlines()[0]})",
                "start the world with MUJOCO_GL=egl (or osmesa) in its environment, and an "
                "image no larger than the model's <visual><global offwidth/offheight>",
            ) from exc
        if self.spec.depth:
            renderer.enable_depth_rendering()
        self._renderer = renderer
        return renderer

    def _close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
