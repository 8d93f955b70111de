"""Gazebo's tags and semantics: reading `<gazebo>` values, and applying them to a MuJoCo spec.

`tags` reads values as sdformat does, `blocks` gathers a description's `<gazebo>` blocks into
typed extensions; `apply` (with `joints`, `contact`, `materials`) turns those typed values into
MuJoCo settings: friction by minimum, kp/kd springs, self-collision, gravity, damping, colours.
"""

from __future__ import annotations

from converters.gazebo.apply import apply_gazebo
from converters.gazebo.blocks import parse_gazebo
from converters.gazebo.contact import add_gazebo_ground, friction_priority
from converters.gazebo.materials import gazebo_rgba

__all__ = ["add_gazebo_ground", "apply_gazebo", "friction_priority", "gazebo_rgba", "parse_gazebo"]
