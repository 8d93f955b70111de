"""The world on a live ROS 2 graph over DDS (Cyclone DDS), without ROS installed.

A consumer of the world, like the recorder whose topics, messages and frames it publishes:
`scope` (domain and Cyclone's configuration, loopback only by default), `graph` (DDS names,
types built from rosbags' definitions, QoS), `participant` (writers and readers), `commands`
(cmd_vel in, through `twin drive`'s call), `bridge` (the live recording that feeds the
participant, and the server's service). cyclonedds is imported only when a bridge starts.
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
