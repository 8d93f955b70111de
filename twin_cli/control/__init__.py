"""Controllers of a running world: Gazebo plugins run by twin in sim time (the diff drive).

A controller is a world observer at its own update rate (no Python per physics step) that acts
only through the engine's API (joint commands). Modules: `kinematics` (pure diff-drive rules),
`diff_drive` (one entity's controller), `drives` (a world's controllers, the checked entries).
"""

from __future__ import annotations

from twin_cli.control.diff_drive import DiffDriveController
from twin_cli.control.drives import controller_of, drive, odometry

__all__ = ["DiffDriveController", "controller_of", "drive", "odometry"]
