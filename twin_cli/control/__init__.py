"""Controllers that drive a running world over time, in sim time, as its observers.

`trajectory` reads trajectory_msgs/JointTrajectory files and interpolates them as
joint_trajectory_controller does; `follower` follows one on an entity at the controller
manager's update rate and reports the tracking error.
"""

from __future__ import annotations

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
    "TrackingReport",
    "Trajectory",
    "TrajectoryFollower",
    "TrajectoryPoint",
    "follow_trajectory",
    "read_trajectory",
    "sample",
    "tracking_report",
    "trajectory_from_dict",
]
