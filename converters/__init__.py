"""Robot descriptions (xacro, URDF with Gazebo tags) → MuJoCo MjSpec with Gazebo's physics."""

from __future__ import annotations

from converters.errors import ConversionError
from converters.report import Outcome, Report

__all__ = ["ConversionError", "Outcome", "Report"]
