"""The QoS each of a world's topics is offered with, as ROS 2's own publishers offer it.

- rclcpp's default: reliable, volatile, keep last 10 (`/clock`, `/tf`, joint states, odometry);
- latched topics (`/tf_static`, `robot_description`): reliable, transient local, keep last 1,
  as tf2_ros' StaticTransformBroadcaster and robot_state_publisher offer them;
- sensor topics: best effort, volatile, keep last 5 (rclcpp's SensorDataQoS, which gazebo_ros'
  sensor plugins use).

The live bridge's writers (`twin_cli.ros.graph`) and a bag's channels (`mcap_writer`) both take
it from here, so `ros2 bag play` offers what the live graph offered.
"""

from __future__ import annotations

from dataclasses import dataclass

from twin_cli.record.sensor_messages import sensor_types
from twin_cli.record.topics import Topic


@dataclass(frozen=True)
class Qos:
    """A topic's QoS: reliable or best effort; transient local or volatile; keep last `depth`."""

    reliable: bool
    transient_local: bool
    depth: int


DEFAULT_QOS = Qos(reliable=True, transient_local=False, depth=10)
LATCHED_QOS = Qos(reliable=True, transient_local=True, depth=1)
SENSOR_QOS = Qos(reliable=False, transient_local=False, depth=5)


def qos_of(topic: Topic) -> Qos:
    """The QoS ROS's own publisher of `topic` offers (see module docstring)."""
    if topic.latched:
        return LATCHED_QOS
    return SENSOR_QOS if topic.type in sensor_types() else DEFAULT_QOS
