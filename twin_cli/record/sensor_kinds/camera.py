"""A camera's message: sensor_msgs/Image on `<topic>/image_raw`, as gazebo_ros' cameras publish
it (rgb8, or 32FC1 metres for a depth camera; little-endian rows)."""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description.sensors import CameraSpec
from twin_cli.record.sensor_messages import ros_message
from twin_cli.sensors import ImageReading

IMAGE = "sensor_msgs/msg/Image"
PIXEL_BYTES = {"rgb8": 3, "32FC1": 4}  # bytes per pixel of each encoding


@ros_message(CameraSpec, ImageReading, IMAGE, suffix="/image_raw")
def image_message(T: Any, header: Any, r: ImageReading) -> Any:
    return T[IMAGE](
        header=header,
        height=r.height,
        width=r.width,
        encoding=r.encoding,
        is_bigendian=0,
        step=r.width * PIXEL_BYTES[r.encoding],
        data=np.frombuffer(r.data, dtype=np.uint8),
    )
