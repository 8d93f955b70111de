"""A ray sensor's message: sensor_msgs/LaserScan of its first vertical row (gazebo_ros' laser)."""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description.sensors import RaySpec
from twin_cli.record.sensor_messages import ros_message
from twin_cli.sensors import ScanReading

SCAN = "sensor_msgs/msg/LaserScan"


@ros_message(RaySpec, ScanReading, SCAN)
def scan_message(T: Any, header: Any, r: ScanReading) -> Any:
    row = len(r.ranges) // max(1, r.vertical_count)
    return T[SCAN](
        header=header,
        angle_min=r.angle_min,
        angle_max=r.angle_max,
        angle_increment=r.angle_increment,
        time_increment=0.0,
        scan_time=r.scan_time,
        range_min=r.range_min,
        range_max=r.range_max,
        ranges=np.asarray(r.ranges[:row], dtype=np.float32),
        intensities=np.zeros(0, dtype=np.float32),
    )
