"""Drives that the robot's ros2_control controllers declare: diff_drive_controller.

A ROS 2 robot simulated with gazebo_ros2_control (or gz_ros2_control) usually has no drive
plugin: its wheels offer velocity command interfaces in `<ros2_control>`, and a controller of type
`diff_drive_controller/DiffDriveController` in the controller manager's parameter file turns
them from `cmd_vel`. twin runs that controller as a differential drive (`DiffDrive`, family
"diff_drive_controller"), with its parameters read under ros2_control's names and defaults:

- `left_wheel_names`, `right_wheel_names`, `wheel_separation`, `wheel_radius` (required), times
  `wheel_separation_multiplier` and the wheel radius multipliers;
- `linear.x.max_velocity`, `angular.z.max_velocity` clip the twist; `linear.x.max_acceleration`
  ramps the wheels' rim speeds (limits count where the value is a finite number and, in the
  older form, its `has_velocity_limits` / `has_acceleration_limits` flag is not false);
- odometry from the wheels' joint positions, in `odom_frame_id` → `base_frame_id`;
- the controller manager's `update_rate` (default 100 Hz).
What twin does not reproduce is listed tag by tag in the record's notes.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from converters.description.gazebo import Blob
from converters.errors import InputFileError
from converters.gazebo.controller_yaml import (
    MANAGER,
    controller_types,
    load_parameters,
    node_parameters,
    parameter,
    parameter_files,
)
from converters.gazebo.drive_records import DiffDrive

DIFF_DRIVE_TYPE = "diff_drive_controller/DiffDriveController"
FAMILY = "diff_drive_controller"
DEFAULT_UPDATE_RATE = 100.0  # [Hz] the controller manager's default update_rate
# Parameters twin reads as the controller does, and ones it does not reproduce (with why).
NOT_RUN = {
    "cmd_vel_timeout": "a command holds until the next one (`twin drive -d` sets a duration)",
    "open_loop": "odometry is always integrated from the wheels' joint positions",
    "position_feedback": "odometry is always integrated from the wheels' joint positions",
    "enable_odom_tf": "`twin serve --ros` always publishes the odom frame in /tf",
    "tf_frame_prefix_enable": "frames are prefixed with the entity's name",
    "tf_frame_prefix": "frames are prefixed with the entity's name",
    "angular.z.max_acceleration": "the wheels ramp at linear.x.max_acceleration at the rim",
    "linear.x.min_velocity": "the twist is clipped symmetrically at max_velocity",
    "angular.z.min_velocity": "the twist is clipped symmetrically at max_velocity",
    "linear.x.max_jerk": "no jerk limit",
    "angular.z.max_jerk": "no jerk limit",
    "velocity_rolling_window_size": "odometry is not averaged over a window",
}


def read_controller_drives(
    blob: Blob, source: str
) -> tuple[tuple[DiffDrive, ...], tuple[str, ...]]:
    """Every diff_drive_controller in the parameter files a ros2_control plugin names.

    Returns:
        The drives, and a note for each parameter file that could not be read (the plugin's
        command interfaces still work without it).

    Raises:
        InputFileError: a diff_drive_controller parameter that is missing or not a number (the
            message names the file, controller and parameter).
    """
    drives: list[DiffDrive] = []
    problems: list[str] = []
    for path in parameter_files(blob.xml, source):
        document = load_parameters(path)
        if isinstance(document, str):
            problems.append(f"{path} not read ({document}): no controllers from it")
            continue
        rate = _number(node_parameters(document, MANAGER), "update_rate", path, MANAGER)
        for name, kind in controller_types(document).items():
            if kind == DIFF_DRIVE_TYPE:
                params = node_parameters(document, name)
                drives.append(_diff_drive(name, params, path, rate or DEFAULT_UPDATE_RATE))
    return tuple(drives), tuple(problems)


def _diff_drive(name: str, params: dict, path: Path, rate: float) -> DiffDrive:
    """One diff_drive_controller's parameters as a `DiffDrive` record."""
    left = _wheels(params, "left_wheel_names", path, name)
    right = _wheels(params, "right_wheel_names", path, name)
    separation = _required(params, "wheel_separation", path, name)
    separation *= _number(params, "wheel_separation_multiplier", path, name) or 1.0
    radius = _required(params, "wheel_radius", path, name)
    multipliers = [
        _number(params, key, path, name) or 1.0
        for key in ("left_wheel_radius_multiplier", "right_wheel_radius_multiplier")
    ]
    notes = [f"{DIFF_DRIVE_TYPE} '{name}' from {path}: run by twin as a differential drive"]
    if multipliers[0] != multipliers[1]:
        notes.append(
            f"left/right_wheel_radius_multiplier {multipliers[0]}/{multipliers[1]}: both wheels "
            "use their mean"
        )
    notes += [f"{key}: {why}" for key, why in NOT_RUN.items() if parameter(params, key) is not None]
    return DiffDrive(
        name=name,
        where=f"{path} {name}",
        left_joints=left,
        right_joints=right,
        wheel_separation=separation,
        wheel_diameter=radius * (multipliers[0] + multipliers[1]),
        max_wheel_torque=math.inf,  # the speed is set; the joint's own motor bounds it
        max_wheel_acceleration=_limit(params, "linear.x", "acceleration", path, name) or 0.0,
        odometry_source="encoder",
        update_rate=rate,
        family=FAMILY,
        odometry_frame=str(parameter(params, "odom_frame_id", "odom")),
        robot_base_frame=str(parameter(params, "base_frame_id", "base_link")),
        max_linear_velocity=_limit(params, "linear.x", "velocity", path, name) or math.inf,
        max_angular_velocity=_limit(params, "angular.z", "velocity", path, name) or math.inf,
        notes=tuple(notes),
    )


def _wheels(params: dict, key: str, path: Path, controller: str) -> tuple[str, ...]:
    value = parameter(params, key)
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise InputFileError(
            str(path),
            f"controller '{controller}' ({DIFF_DRIVE_TYPE}): {key} is {value!r}, not a list of "
            "wheel joint names",
            f'write e.g. {key}: ["{key.split("_")[0]}_wheel_joint"] under its ros__parameters',
        )
    return tuple(value)


def _required(params: dict, key: str, path: Path, controller: str) -> float:
    value = _number(params, key, path, controller)
    if value is None or not value > 0:
        raise InputFileError(
            str(path),
            f"controller '{controller}' ({DIFF_DRIVE_TYPE}): {key} is "
            f"{parameter(params, key)!r}, not a length > 0 [m]",
            f"write e.g. {key}: 0.3 under its ros__parameters",
        )
    return value


def _number(params: dict, key: str, path: Path, controller: str) -> float | None:
    """A numeric parameter, None when absent or NaN (ros2_control's "unset")."""
    value: Any = parameter(params, key)
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputFileError(
            str(path),
            f"controller '{controller}': {key} is {value!r}, not a number",
            f"write a plain number for {key} under its ros__parameters",
        )
    return None if math.isnan(value) else float(value)


def _limit(params: dict, axis: str, kind: str, path: Path, controller: str) -> float | None:
    """`<axis>.max_<kind>` where it limits: a finite number whose `has_<kind>_limits` flag (the
    older form) is not false."""
    if parameter(params, f"{axis}.has_{kind}_limits") is False:
        return None
    value = _number(params, f"{axis}.max_{kind}", path, controller)
    return abs(value) if value is not None and math.isfinite(value) and value != 0 else None
