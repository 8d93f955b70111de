"""The IMU's message: sensor_msgs/Imu, covariances unknown (all zeros), as gazebo_ros' IMU."""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description.sensors import ImuSpec
from twin_cli.record.sensor_messages import ros_message, vector3
from twin_cli.sensors import ImuReading

IMU = "sensor_msgs/msg/Imu"
UNKNOWN_COVARIANCE = np.zeros(9)  # sensor_msgs: all zeros = "covariance unknown"


@ros_message(ImuSpec, ImuReading, IMU)
def imu_message(T: Any, header: Any, r: ImuReading) -> Any:
    x, y, z, w = (float(c) for c in r.orientation)
    return T[IMU](
        header=header,
        orientation=T["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w),
        orientation_covariance=UNKNOWN_COVARIANCE,
        angular_velocity=vector3(T, r.angular_velocity),
        angular_velocity_covariance=UNKNOWN_COVARIANCE,
        linear_acceleration=vector3(T, r.linear_acceleration),
        linear_acceleration_covariance=UNKNOWN_COVARIANCE,
    )
