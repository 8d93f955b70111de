"""Controllers that drive a running world over time, in sim time, as its observers.

Each controller is a world observer at its own update rate (a drive's: its plugin's) that acts
only through the engine's API (joint commands). `trajectory` reads
trajectory_msgs/JointTrajectory files and interpolates them as joint_trajectory_controller does;
`follower` follows one on an entity at the controller manager's update rate and reports the
tracking error; `drives` runs a robot's drive plugin (`drive_base` with `diff_drive`,
`steered_drive`, `holonomic_drive`; maths in `kinematics` and `steering`).

Exports are lazy (`twin_cli.lazy`): `twin trajectory` reads its file with `trajectory` on the
client, which must not import mujoco or numpy through this package.
"""

from __future__ import annotations

from twin_cli.lazy import lazy_getattr

_WHERE = {
    "DiffDriveController": "twin_cli.control.diff_drive",
    "DriveController": "twin_cli.control.drive_base",
    "HolonomicController": "twin_cli.control.holonomic_drive",
    "SteeredDriveController": "twin_cli.control.steered_drive",
    "Twist": "twin_cli.control.drive_base",
    "controller_of": "twin_cli.control.drives",
    "drive": "twin_cli.control.drives",
    "odometry": "twin_cli.control.drives",
    "release_joints": "twin_cli.control.drives",
    "UPDATE_RATE": "twin_cli.control.follower",
    "TrackingReport": "twin_cli.control.follower",
    "TrajectoryFollower": "twin_cli.control.follower",
    "follow_trajectory": "twin_cli.control.follower",
    "tracking_report": "twin_cli.control.follower",
    "Trajectory": "twin_cli.control.trajectory",
    "TrajectoryPoint": "twin_cli.control.trajectory",
    "read_trajectory": "twin_cli.control.trajectory",
    "sample": "twin_cli.control.trajectory",
    "trajectory_from_dict": "twin_cli.control.trajectory",
}
__all__ = sorted(_WHERE)
__getattr__ = lazy_getattr("twin_cli.control", _WHERE)
