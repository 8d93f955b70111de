"""The neutral robot description: what format readers produce and every later stage consumes.

`robot` holds links, joints, shapes and inertials; `gazebo` holds Gazebo's typed values
(surfaces, link and joint flags, plugins and sensors); `world` holds a world's physics, lights
and placed models. Nothing here knows a file format.
"""

from __future__ import annotations

from converters.description.control import (
    CONTROL_PLUGINS,
    HARDWARE_INTERFACES,
    MODES,
    CommandInterface,
    JointControl,
    PidGains,
    is_control_plugin,
    merge_controls,
)
from converters.description.gazebo import (
    Blob,
    GazeboExtensions,
    InlineSurface,
    JointExtension,
    LinkExtension,
    Surface,
    TagSource,
)
from converters.description.robot import (
    JOINT_TYPES,
    SHAPES,
    WORLD_LINK,
    Collision,
    Dynamics,
    Frame,
    Geometry,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mimic,
    RobotDescription,
    Visual,
)
from converters.description.world import Light, PlacedModel, WorldDescription

__all__ = [
    "CONTROL_PLUGINS",
    "is_control_plugin",
    "HARDWARE_INTERFACES",
    "MODES",
    "CommandInterface",
    "JointControl",
    "PidGains",
    "merge_controls",
    "JOINT_TYPES",
    "SHAPES",
    "WORLD_LINK",
    "Blob",
    "Collision",
    "Dynamics",
    "Frame",
    "GazeboExtensions",
    "Geometry",
    "Inertial",
    "InlineSurface",
    "Joint",
    "JointExtension",
    "Limit",
    "Light",
    "Link",
    "LinkExtension",
    "Material",
    "Mimic",
    "PlacedModel",
    "RobotDescription",
    "Surface",
    "TagSource",
    "Visual",
    "WorldDescription",
]
