"""Controllers that drive a running world over time, in sim time, as its observers.

Each controller is a world observer at its own update rate (no Python per physics step) that acts
only through the engine's API (joint commands). `trajectory` reads
trajectory_msgs/JointTrajectory files and interpolates them as joint_trajectory_controller does;
`follower` follows one on an entity at the controller manager's update rate and reports the
tracking error; `kinematics`, `diff_drive` and `drives` run gazebo_ros' diff-drive plugin.
"""

from __future__ import annotations

from twin_cli.control.diff_drive import DiffDriveController
from twin_cli.control.drives import controller_of, drive, odometry
from twin_cli.control.follower import (
    UPDATE_RATE,
    TrackingReport,
    TrajectoryFollower,
    follow_trajectory,
    tracking_report,
)
from twin_cli.control.trajectory import (
    Trajectory,
    TrajectoryPoint,
    read_trajectory,
    sample,
    trajectory_from_dict,
)

__all__ = [
    "UPDATE_RATE",
    "DiffDriveController",
    "TrackingReport",
    "Trajectory",
    "TrajectoryFollower",
    "TrajectoryPoint",
    "controller_of",
    "drive",
    "follow_trajectory",
    "odometry",
    "read_trajectory",
    "sample",
    "tracking_report",
    "trajectory_from_dict",
]
