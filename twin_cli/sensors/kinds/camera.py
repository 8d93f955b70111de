"""Camera and depth camera: offscreen rendering of the sensor's MuJoCo camera, where GL exists.

The converter gives each camera sensor a MuJoCo camera `sensor:<name>` looking along the
sensor's +x (Gazebo's convention) with the vertical field of view of its horizontal one and
aspect. Rendering needs an offscreen OpenGL context, which MuJoCo picks when it is first
imported (`MUJOCO_GL=egl` or `osmesa`; measured: EGL on Mesa llvmpipe ~17 frames/s at
320×240). Without one, reading the camera fails with a message saying how to get one; the
other sensors keep working. Depth images are metres along the view axis (32FC1).

The sensor's `<clip>` planes replace the model's global ones (`<visual><map znear zfar>`) in
the rendered scene's frustum. A colour camera is clipped at near and far, as Gazebo's is. A depth
camera, as gz-sensors' (REP 117), is rendered from DEPTH_NEAR so that an object nearer than the
near plane still hides what is behind it, then reports −inf where the depth is ≤ near and +inf
where it is ≥ far (nothing within range). MuJoCo's renderer converts depth with the model's
planes, so depth frames are rendered and converted here, with the sensor's (reversed Z:
1 at the near plane, 0 at the far one).
"""

from __future__ import annotations

import os
import threading

import mujoco
import numpy as np

from converters.description.sensors import CameraSpec
from twin_cli.errors import InvalidRequestError
from twin_cli.sensors.frames import element_id
from twin_cli.sensors.readings import ImageReading
from twin_cli.sensors.registry import sensor_for

DEPTH_NEAR = 0.01  # [m] near plane a depth camera is rendered from (gz-rendering's default)


@sensor_for(CameraSpec, kinematic=True)
class CameraSensor:
    """One camera (`camera`, `depth`, `rgbd_camera`, ...) of an entity."""

    def __init__(self, spec: CameraSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.camera = -1
        self._renderer: mujoco.Renderer | None = None
        self._lock = threading.Lock()  # one GL context: one render at a time

    def bind(self, model: mujoco.MjModel) -> None:
        name = f"{self.entity}/{self.spec.site}"
        self.camera = element_id(model, mujoco.mjtObj.mjOBJ_CAMERA, "camera", name, self.entity)
        self._close()

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> ImageReading:
        """Raises: InvalidRequestError: no offscreen GL here, or the image is too large."""
        with self._lock:
            renderer = self._open(model)
            renderer.update_scene(data, camera=self.camera)
            if self.spec.depth:
                pixels = _render_depth(renderer, self.spec.near, self.spec.far)
            else:
                _clip(renderer.scene, self.spec.near, self.spec.far)
                pixels = renderer.render()
        encoding = "32FC1" if self.spec.depth else "rgb8"
        raw = pixels.astype(np.float32 if self.spec.depth else np.uint8).tobytes()
        return ImageReading(
            self.spec.name, self.spec.type, time, self.spec.frame_id,
            self.spec.width, self.spec.height, encoding, raw,
        )  # fmt: skip

    def _open(self, model: mujoco.MjModel) -> mujoco.Renderer:
        if self._renderer is not None:
            # Requests run on pool threads; mujoco.Renderer keeps its GL context private.
            self._renderer._gl_context.make_current()  # noqa: SLF001
            return self._renderer
        if _window_backend() and threading.current_thread() is not threading.main_thread():
            # GLFW may only start on the main thread: elsewhere it aborts the process.
            raise self._unavailable("MUJOCO_GL selects GLFW, which renders on the main thread only")
        try:
            renderer = mujoco.Renderer(model, self.spec.height, self.spec.width)
        except (mujoco.FatalError, RuntimeError, ValueError) as exc:
            raise self._unavailable(str(exc).splitlines()[0]) from exc
        self._renderer = renderer
        return renderer

    def _unavailable(self, why: str) -> InvalidRequestError:
        return InvalidRequestError(
            f"camera sensor '{self.spec.name}' of [{self.entity}]",
            f"cannot render offscreen ({why})",
            "start the world with MUJOCO_GL=egl (or osmesa) in its environment, and an "
            "image no larger than the model's <visual><global offwidth/offheight>",
        )

    def _close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def _window_backend() -> bool:
    """Whether MuJoCo renders through GLFW here (MUJOCO_GL unset or glfw: a desktop's window)."""
    return os.environ.get("MUJOCO_GL", "glfw").lower() in ("", "glfw")


def _clip(scene: mujoco.MjvScene, near: float, far: float) -> None:
    """Sets the frustum planes [m] of the scene's cameras (both eyes) after `update_scene`.

    MuJoCo sizes the frustum at its near plane, so its extents scale with it (same view angle).
    """
    for camera in scene.camera:
        scale = near / camera.frustum_near
        camera.frustum_center *= scale
        camera.frustum_width *= scale
        camera.frustum_bottom *= scale
        camera.frustum_top *= scale
        camera.frustum_near, camera.frustum_far = near, far


def _render_depth(renderer: mujoco.Renderer, near: float, far: float) -> np.ndarray:
    """Depth [m] along the view axis, top row first: −inf nearer than `near`, +inf from `far`.

    Uses the renderer's own GL context and buffers (`mujoco.Renderer` has no public call that
    renders with other clip planes than the model's); segmentation mode, as its depth mode,
    leaves the skybox and lighting out.
    """
    render_near = min(DEPTH_NEAR, near)
    _clip(renderer.scene, render_near, far)
    flags = renderer.scene.flags
    saved = flags.copy()
    flags[mujoco.mjtRndFlag.mjRND_SEGMENT] = flags[mujoco.mjtRndFlag.mjRND_IDCOLOR] = True
    try:
        buffer = np.empty((renderer.height, renderer.width), np.float32)
        # A float segmentation read needs mjr_* on the Renderer's own viewport and context.
        rect, context = renderer._rect, renderer._mjr_context  # noqa: SLF001
        mujoco.mjr_render(rect, renderer.scene, context)
        mujoco.mjr_readPixels(None, buffer, rect, context)
    finally:
        np.copyto(flags, saved)
    reversed_z = np.flipud(buffer).astype(np.float64)  # GL rows are bottom first
    with np.errstate(divide="ignore"):
        depth = render_near * far / (render_near + reversed_z * (far - render_near))
    depth[(reversed_z <= 0.0) | (depth >= far)] = np.inf
    depth[depth <= near] = -np.inf
    return depth.astype(np.float32)
