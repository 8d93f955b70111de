"""A force/torque sensor's message: geometry_msgs/WrenchStamped (gazebo_ros' F/T plugin)."""

from __future__ import annotations

from typing import Any

from converters.description.sensors import ForceTorqueSpec
from twin_cli.record.sensor_messages import ros_message, vector3
from twin_cli.sensors import WrenchReading

WRENCH = "geometry_msgs/msg/WrenchStamped"


@ros_message(ForceTorqueSpec, WrenchReading, WRENCH)
def wrench_message(T: Any, header: Any, r: WrenchReading) -> Any:
    wrench = T["geometry_msgs/msg/Wrench"](force=vector3(T, r.force), torque=vector3(T, r.torque))
    return T[WRENCH](header=header, wrench=wrench)
