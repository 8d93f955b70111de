"""`<sensor type="camera">` and depth cameras: SDF `camera.sdf` (image, field of view, clip)."""

from __future__ import annotations

from typing import Any

from converters.description.sensors import CameraSpec
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind

DEPTH_TYPES = frozenset({"depth", "depth_camera", "rgbd_camera"})


@sensor_kind("camera", "camera", "depth", "depth_camera", "rgbd_camera", "wideanglecamera")
def read_camera(reader: SensorReader, common: dict[str, Any], placement: Placement) -> CameraSpec:
    """Image size [px], horizontal field of view [rad], clip planes [m], format and noise.

    Raises:
        GazeboTagError: the clip planes are not 0 < near < far.
    """
    camera = reader.el.find("camera")
    if camera is None:
        return CameraSpec(**common, depth=common["type"].lower() in DEPTH_TYPES)
    near = reader.number("clip/near", 0.1, camera)
    far = reader.number("clip/far", 100.0, camera)
    if not 0.0 < near < far:
        expected = "0 < near < far (metres)"
        raise reader.ctx.fail(
            f"{reader.prefix} camera/clip", f"near {near:g} far {far:g}", expected
        )
    return CameraSpec(
        **common,
        width=reader.integer("image/width", 320, camera),
        height=reader.integer("image/height", 240, camera),
        horizontal_fov=reader.number("horizontal_fov", 1.047, camera),
        near=near,
        far=far,
        image_format=reader.text("image/format", "R8G8B8", camera),
        depth=common["type"].lower() in DEPTH_TYPES,
        noise=reader.noise(camera.find("noise")),
    )
