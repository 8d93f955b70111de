"""Drives that the robot's ros2_control controllers declare: diff_drive_controller.

A ROS 2 robot simulated with gazebo_ros2_control (or gz_ros2_control) usually has no drive
plugin: its wheels offer velocity command interfaces in `<ros2_control>`, and a controller of type
`diff_drive_controller/DiffDriveController` in the controller manager's parameter file turns
them from `cmd_vel`. twin runs that controller as a differential drive (`DiffDrive`, family
"diff_drive_controller"), with its parameters read under ros2_control's names and defaults:

- `left_wheel_names`, `right_wheel_names`, `wheel_separation`, `wheel_radius` (required), times
  `wheel_separation_multiplier` and the wheel radius multipliers;
- `linear.x.*` and `angular.z.*` speed limiters bound the twist: `max_velocity`/`min_velocity`,
  and the change of each by `max_acceleration` and a braking bound (Humble: `min_acceleration`;
  Jazzy: `max_deceleration`, and backward `max_acceleration_reverse`/
  `max_deceleration_reverse`, by the sign of the last command). A limit counts where its value
  is a number and its `has_velocity_limits` / `has_acceleration_limits` flag is true (Humble's
  rule, which Gazebo Classic's gazebo_ros2_control runs) or not false (Jazzy's, for
  gz_ros2_control);
- `cmd_vel_timeout` (default 0.5 s): a cmd_vel taken over ROS holds that long;
- odometry from the wheels' joint positions, in `odom_frame_id` → `base_frame_id`, on the
  controller's `~/odom` (`<ns>/<controller>/odom`);
- the controller manager's `update_rate` (default 100 Hz).
What twin does not reproduce is listed tag by tag in the record's notes.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from converters.description.gazebo import Blob
from converters.errors import InputFileError
from converters.gazebo.controller_yaml import (
    controller_types,
    load_parameters,
    manager_name,
    merged_nodes,
    node_parameters,
    parameter,
    parameter_files,
)
from converters.gazebo.drive_records import DiffDrive
from converters.gazebo.plugin_params import Params

DIFF_DRIVE_TYPE = "diff_drive_controller/DiffDriveController"
FAMILY = "diff_drive_controller"
DEFAULT_UPDATE_RATE = 100.0  # [Hz] the controller manager's default update_rate
DEFAULT_CMD_VEL_TIMEOUT = 0.5  # [s] the controller stops the wheels this long after a command
# Gazebo Classic's plugin runs Humble's controllers: a limit counts only with its has_*_limits
# flag set (Jazzy's count wherever the value is a number).
FLAGGED_LIMIT_PLUGINS = ("libgazebo_ros2_control.so", "gazebo_ros2_control")
# Parameters twin does not reproduce, with what it does instead.
NOT_RUN = {
    "open_loop": "odometry is always integrated from the wheels' joint positions",
    "position_feedback": "odometry is always integrated from the wheels' joint positions",
    "enable_odom_tf": "`twin serve --ros` always publishes the odom frame in /tf",
    "tf_frame_prefix_enable": "frames are prefixed with the entity's name",
    "tf_frame_prefix": "frames are prefixed with the entity's name",
    "preserve_turning_radius": "v and ω are bounded each on its own, as Humble's controller",
    "linear.x.max_jerk": "no jerk limit",
    "angular.z.max_jerk": "no jerk limit",
    "velocity_rolling_window_size": "odometry is not averaged over a window",
}


def read_controller_drives(
    blob: Blob, source: str, base: Path, joints: set[str] | None = None
) -> tuple[tuple[DiffDrive, ...], tuple[str, ...]]:
    """Every diff_drive_controller in the parameter files a ros2_control plugin names.

    Args:
        blob: the plugin; source: the description, for messages; base: where relative
            `<parameters>` paths start; joints: the model's joints (None: not checked).

    Returns:
        The drives, and a note for each parameter file that could not be read and for each
        listed drive whose parameters were not found (the plugin's command interfaces still
        work without them).

    Raises:
        InputFileError: a diff_drive_controller parameter that is missing, not a number or
            names a joint the model does not have (the message names the file, controller and
            parameter).
    """
    documents: list[dict] = []
    problems: list[str] = []
    paths = parameter_files(blob.xml, base)
    for path in paths:
        document = load_parameters(path)
        if isinstance(document, str):
            problems.append(f"{path} not read ({document}): no controllers from it")
        else:
            documents.append(document)
    nodes = merged_nodes(documents)
    manager = manager_name(blob.xml)
    where = ", ".join(str(p) for p in paths)
    rate = _number(node_parameters(nodes, manager), "update_rate", where, manager)
    limits_need_flags = (blob.kind or "").rsplit("/", 1)[-1] in FLAGGED_LIMIT_PLUGINS
    drives = []
    for name, kind in controller_types(nodes, manager).items():
        if kind != DIFF_DRIVE_TYPE:
            continue
        params = node_parameters(nodes, name)
        if not any(k != "type" for k in params):
            problems.append(f"{DIFF_DRIVE_TYPE} '{name}': no parameters for it in {where}")
            continue
        drive = _diff_drive(name, params, where, rate or DEFAULT_UPDATE_RATE, limits_need_flags)
        drive = replace(drive, odom_topic=Params.of(blob, source).ros_topic(f"{name}/odom"))
        _check_joints(drive, params, where, joints)
        drives.append(drive)
    return tuple(drives), tuple(problems)


def _diff_drive(name: str, params: dict, where: str, rate: float, flags: bool) -> DiffDrive:
    """One diff_drive_controller's parameters as a `DiffDrive` record."""
    left = _wheels(params, "left_wheel_names", where, name)
    right = _wheels(params, "right_wheel_names", where, name)
    separation = _required(params, "wheel_separation", where, name)
    separation *= _number(params, "wheel_separation_multiplier", where, name) or 1.0
    radius = _required(params, "wheel_radius", where, name)
    multipliers = [
        _number(params, key, where, name) or 1.0
        for key in ("left_wheel_radius_multiplier", "right_wheel_radius_multiplier")
    ]
    timeout = _number(params, "cmd_vel_timeout", where, name)
    timeout = DEFAULT_CMD_VEL_TIMEOUT if timeout is None else max(timeout, 0.0)
    notes = [
        f"{DIFF_DRIVE_TYPE} '{name}' from {where}: run by twin as a differential drive; a "
        f"cmd_vel over ROS holds for cmd_vel_timeout {timeout:g} s (`twin drive` until replaced "
        "or -d)"
    ]
    if multipliers[0] != multipliers[1]:
        notes.append(
            f"left/right_wheel_radius_multiplier {multipliers[0]}/{multipliers[1]}: both wheels "
            "use their mean"
        )
    notes += [f"{key}: {why}" for key, why in NOT_RUN.items() if parameter(params, key) is not None]
    if not flags:  # Jazzy's controller declares it but passes it to no limiter
        notes += [
            f"{axis}.min_acceleration: not used by Jazzy's controller (use max_deceleration)"
            for axis in ("linear.x", "angular.z")
            if parameter(params, f"{axis}.min_acceleration") is not None
        ]
    return DiffDrive(
        name=name,
        where=f"{where} {name}",
        left_joints=left,
        right_joints=right,
        wheel_separation=separation,
        wheel_diameter=radius * (multipliers[0] + multipliers[1]),
        max_wheel_torque=math.inf,  # the speed is set; the joint's own motor bounds it
        max_wheel_acceleration=0.0,  # the twist is bounded instead
        twist_acceleration=_twist_acceleration(params, where, name, flags),
        reverse_acceleration=None if flags else _reverse_acceleration(params, where, name),
        odometry_source="encoder",
        update_rate=rate,
        family=FAMILY,
        odometry_frame=str(parameter(params, "odom_frame_id", "odom")),
        robot_base_frame=str(parameter(params, "base_frame_id", "base_link")),
        max_linear_velocity=_limit(params, "linear.x", "velocity", where, name, flags, math.inf),
        max_angular_velocity=_limit(params, "angular.z", "velocity", where, name, flags, math.inf),
        min_velocities=_min_velocities(params, where, name, flags),
        command_timeout=timeout,
        notes=tuple(notes),
    )


def _check_joints(drive: DiffDrive, params: dict, where: str, joints: set[str] | None) -> None:
    for key, names in (
        ("left_wheel_names", drive.left_joints),
        ("right_wheel_names", drive.right_joints),
    ):
        for joint in names:
            if joints is not None and joint not in joints:
                raise InputFileError(
                    where,
                    f"controller '{drive.name}' ({DIFF_DRIVE_TYPE}): {key} names joint "
                    f"'{joint}', which the model does not have",
                    f"name one of its joints ({', '.join(sorted(joints)) or 'none'})",
                )


def _wheels(params: dict, key: str, path: str, controller: str) -> tuple[str, ...]:
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


def _required(params: dict, key: str, path: str, controller: str) -> float:
    value = _number(params, key, path, controller)
    if value is None or not value > 0:
        raise InputFileError(
            str(path),
            f"controller '{controller}' ({DIFF_DRIVE_TYPE}): {key} is "
            f"{parameter(params, key)!r}, not a length > 0 [m]",
            f"write e.g. {key}: 0.3 under its ros__parameters",
        )
    return value


def _number(params: dict, key: str, path: str, controller: str) -> float | None:
    """A numeric parameter, None when absent or NaN (ros2_control's "unset"). A string that is a
    number counts: YAML 1.1 reads `5e-2` as text, ROS's parser as a double."""
    value: Any = parameter(params, key)
    if value is None:
        return None
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            pass
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputFileError(
            str(path),
            f"controller '{controller}': {key} is {value!r}, not a number",
            f"write a plain number for {key} under its ros__parameters",
        )
    return None if math.isnan(value) else float(value)


def _min_velocities(
    params: dict, path: str, controller: str, flags: bool
) -> tuple[float, float] | None:
    """linear.x and angular.z `min_velocity` (signed) where a velocity limit applies and one is
    given, else -max_velocity (the speed limiter's default); None when neither is given."""
    lows: list[float] = []
    given_any = False
    for axis in ("linear.x", "angular.z"):
        top = _limit(params, axis, "velocity", path, controller, flags, math.inf)
        given = _number(params, f"{axis}.min_velocity", path, controller)
        if math.isfinite(top) and given is not None and math.isfinite(given):
            lows.append(given)
            given_any = True
        else:
            lows.append(-top)
    return (lows[0], lows[1]) if given_any else None


def _twist_acceleration(
    params: dict, path: str, controller: str, flags: bool
) -> tuple[float, float, float, float]:
    """(min, max) change of linear.x [m/s²], then of angular.z [rad/s²], while the command is
    forward, as the controller's speed limiters bound it; no limit: ±inf. Where
    `max_acceleration` limits (`_limit`): Humble (`flags`) brakes at `min_acceleration`
    (signed), else -max; Jazzy's rate limiter ignores `min_acceleration` and brakes at
    `max_deceleration`, else `max_acceleration_reverse`, else -max."""
    bounds: list[float] = []
    names = ("min_acceleration",) if flags else ("max_deceleration", "max_acceleration_reverse")
    for axis in ("linear.x", "angular.z"):
        top = _limit(params, axis, "acceleration", path, controller, flags, math.inf)
        low = -math.inf
        if math.isfinite(top):
            found = (_given(params, axis, name, path, controller) for name in names)
            given = next((v for v in found if v is not None), None)
            low = -top if given is None else given if flags else -abs(given)
        bounds += [low, top]
    return bounds[0], bounds[1], bounds[2], bounds[3]


def _reverse_acceleration(
    params: dict, path: str, controller: str
) -> tuple[float, float, float, float]:
    """Jazzy's bounds on the change of linear.x, then angular.z, while the command is backward:
    (`max_acceleration_reverse`, else -max; `max_deceleration_reverse`, else +max), ±inf where
    `max_acceleration` does not limit."""
    bounds: list[float] = []
    for axis in ("linear.x", "angular.z"):
        top = _limit(params, axis, "acceleration", path, controller, False, math.inf)
        if not math.isfinite(top):
            bounds += [-math.inf, math.inf]
            continue
        speeding = _given(params, axis, "max_acceleration_reverse", path, controller)
        slowing = _given(params, axis, "max_deceleration_reverse", path, controller)
        bounds += [
            -top if speeding is None else -abs(speeding),
            top if slowing is None else abs(slowing),
        ]
    return bounds[0], bounds[1], bounds[2], bounds[3]


def _given(params: dict, axis: str, name: str, path: str, controller: str) -> float | None:
    """`<axis>.<name>` when it is a finite number, else None (unset, or NaN: Jazzy's unset)."""
    value = _number(params, f"{axis}.{name}", path, controller)
    return value if value is not None and math.isfinite(value) else None


def _limit(
    params: dict,
    axis: str,
    kind: str,
    path: str,
    controller: str,
    flags: bool,
    unlimited: float = 0.0,
) -> float:
    """`<axis>.max_<kind>` where it limits, else `unlimited`: a finite number whose
    `has_<kind>_limits` flag is true (Humble's rule, `flags`) or not false (Jazzy's)."""
    flag = parameter(params, f"{axis}.has_{kind}_limits")
    if flag is False or (flags and flag is not True):
        return unlimited
    value = _number(params, f"{axis}.max_{kind}", path, controller)
    return abs(value) if value is not None and math.isfinite(value) else unlimited
