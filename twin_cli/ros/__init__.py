"""The world on a live ROS 2 graph over DDS (Cyclone DDS), without ROS installed.

A consumer of the world, like the recorder whose topics, messages and frames it publishes:
`scope` (domain and Cyclone's configuration as rmw_cyclonedds_cpp makes it, loopback only by
default), `sockets` (Cyclone's sockets kept on the loopback device), `distro` (the GIDs' size
per ROS 2 distribution), `node` (`ros_discovery_info`), `graph` (DDS names, types built from
rosbags' definitions, QoS), `participant` (writers, readers, service endpoints),
`live_recording` and `publisher` (the world sampled as a bag is, its messages built and
published by a process of their own), `commands` and `plugin_names` (cmd_vel and controller
topics in, under the names the robot's plugins give, through `twin drive`'s and `twin command`'s
calls), `services` and `service_types` (gazebo_ros' entity services), `bridge` (all of it, and
the server's service). cyclonedds is imported only when a bridge starts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.ros.bridge import RosBridge, RosService
    from twin_cli.ros.scope import Scope, cyclone_config, scope_from

__all__ = ["RosBridge", "RosService", "Scope", "cyclone_config", "scope_from"]

__getattr__ = lazy_getattr(
    "twin_cli.ros",
    {
        "RosBridge": "twin_cli.ros.bridge",
        "RosService": "twin_cli.ros.bridge",
        "Scope": "twin_cli.ros.scope",
        "cyclone_config": "twin_cli.ros.scope",
        "scope_from": "twin_cli.ros.scope",
    },
)
