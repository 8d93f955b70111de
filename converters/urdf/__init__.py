"""The URDF reader: xacro expansion without ROS, then URDF text → the robot description."""

from __future__ import annotations

from converters.urdf.reader import parse_urdf
from converters.urdf.xacro_expand import expand_xacro, needs_xacro

__all__ = ["expand_xacro", "needs_xacro", "parse_urdf"]
