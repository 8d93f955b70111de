"""What each drive plugin's tags became, for the report: approximated behaviour, and every given
tag twin does not use.

twin reads a drive's kinematic and limit tags (`drive_readers`); the rest of a plugin's tags
publish ROS topics and TF, set covariances or tune the plugin's own PIDs, which twin replaces by
its servos. The report lists them tag by tag, so a user sees exactly what did not carry over.
"""

from __future__ import annotations

from converters.gazebo import trajectory_controller
from converters.gazebo.plugin_params import Params

ROS_TOPICS = ("ros", "publish", "topic", "covariance", "broadcast", "namespace", "legacy")
"""Tags (by substring) that only publish or name ROS topics and TF: not the drive's to run.
twin's odometry is `twin odom`; on a ROS graph `twin serve --ros` publishes it with tf, named
from the plugin's namespace and remappings."""
ROS_NOTE = "ROS output, not a drive parameter (twin odom; twin serve --ros publishes odom and tf)"

USED: dict[str, set[str]] = {
    "gazebo_ros_diff_drive": {
        "left_joint",
        "right_joint",
        "leftJoint",
        "rightJoint",
        "wheel_separation",
        "wheelSeparation",
        "wheel_diameter",
        "wheelDiameter",
        "max_wheel_torque",
        "wheelTorque",
        "max_wheel_acceleration",
        "wheelAcceleration",
        "odometry_source",
        "odometrySource",
        "update_rate",
        "updateRate",
        "odometry_frame",
        "odometryFrame",
        "robot_base_frame",
        "robotBaseFrame",
    },
    "gazebo_ros_skid_steer_drive": {
        "leftFrontJoint",
        "rightFrontJoint",
        "leftRearJoint",
        "rightRearJoint",
        "wheelSeparation",
        "wheelDiameter",
        "torque",
        "updateRate",
        "odometryFrame",
        "robotBaseFrame",
    },
    "gz-sim-diff-drive-system": {
        "left_joint",
        "right_joint",
        "wheel_separation",
        "wheel_radius",
        "max_linear_acceleration",
        "max_acceleration",
        "min_linear_acceleration",
        "min_acceleration",
        "max_angular_acceleration",
        "min_angular_acceleration",
        "frame_id",
        "child_frame_id",
        "max_linear_velocity",
        "max_velocity",
        "max_angular_velocity",
        "min_linear_velocity",
        "min_velocity",
        "min_angular_velocity",
    },
    "gazebo_ros_ackermann_drive": {
        "front_left_joint",
        "front_right_joint",
        "rear_left_joint",
        "rear_right_joint",
        "left_steering_joint",
        "right_steering_joint",
        "max_steer",
        "max_speed",
        "update_rate",
        "odometry_frame",
        "robot_base_frame",
    },
    "gz-sim-ackermann-steering-system": {
        "left_joint",
        "right_joint",
        "left_steering_joint",
        "right_steering_joint",
        "wheel_base",
        "wheel_separation",
        "kingpin_width",
        "wheel_radius",
        "steering_limit",
        "max_velocity",
        "min_velocity",
        "max_acceleration",
        "min_acceleration",
        "steer_p_gain",
        "frame_id",
        "child_frame_id",
    },
    "gazebo_ros_tricycle_drive": {
        "steering_joint",
        "actuated_wheel_joint",
        "encoder_wheel_left_joint",
        "encoder_wheel_right_joint",
        "actuated_wheel_diameter",
        "encoder_wheel_diameter",
        "wheel_separation",
        "max_wheel_torque",
        "max_wheel_acceleration",
        "max_wheel_deceleration",
        "max_steering_speed",
        "update_rate",
        "odometry_source",
        "odometry_frame",
        "robot_base_frame",
    },
    "gazebo_ros_planar_move": {
        "update_rate",
        "odometry_frame",
        "odometryFrame",
        "robot_base_frame",
        "robotBaseFrame",
    },
    "gz-sim-mecanum-drive-system": {
        "front_left_joint",
        "front_right_joint",
        "back_left_joint",
        "back_right_joint",
        "wheel_radius",
        "wheel_separation",
        "wheelbase",
        "max_velocity",
        "frame_id",
        "child_frame_id",
    },
    "gz-sim-velocity-control-system": {"topic", "initial_linear", "initial_angular"},
    "gz-sim-apply-joint-force-system": {"joint_name"},
    "gz-sim-joint-controller-system": {
        "joint_name",
        "use_force_commands",
        "p_gain",
        "cmd_max",
        "cmd_min",
        "cmd_offset",
        "initial_velocity",  # held from load (twin_cli.world.plugin_holds)
    },
    "gz-sim-joint-position-controller-system": {
        "joint_name",
        "use_velocity_commands",
        "p_gain",
        "i_gain",
        "i_max",
        "i_min",
        "d_gain",
        "cmd_max",
        "cmd_min",
        "cmd_offset",
    },
    "gz-sim-joint-trajectory-controller-system": trajectory_controller.USED,
}

APPROXIMATED: dict[str, tuple[str, ...]] = {
    "gazebo_ros_skid_steer_drive": (
        "four wheels driven as the two sides of a diff drive, as the plugin does; in a turn "
        "they slide sideways and the base turns as their friction lets it, slower than the "
        "command (no heading correction, as in Gazebo)",
    ),
    "gz-sim-diff-drive-system": (
        "speed and acceleration limits on the commanded twist, as its SpeedLimiters apply them; "
        "wheels as velocity servos without a force bound (gz-sim sets their velocity)",
    ),
    "gazebo_ros_ackermann_drive": (
        "rear wheels as velocity servos at their no-slip speeds (the plugin's one PID force on "
        "both is an open differential, which settles at the same speeds); steering joints as "
        "position servos at their Ackermann angles instead of its steering PIDs; wheel base, "
        "track and radius measured on the model, as the plugin does",
    ),
    "gz-sim-ackermann-steering-system": (
        "steering joints commanded its P controller's speed at every step, wheels their "
        "speeds, through velocity servos without a force bound (gz-sim sets joint velocities); "
        "jerk limits not run",
    ),
    "gazebo_ros_tricycle_drive": (
        "steering joint as a position servo (the plugin sets the angle directly); the wheel base "
        "measured on the model",
    ),
    "gazebo_ros_planar_move": (
        "the planar velocity through three velocity servos at the centre of mass, a new command "
        "ramped at 3 m/s² and 6 rad/s² (the plugin sets the velocity in one step)",
    ),
    "gz-sim-joint-trajectory-controller-system": trajectory_controller.APPROXIMATED,
}


PID_TAGS = {"p_gain", "i_gain", "d_gain", "i_max", "i_min", "cmd_max", "cmd_min", "cmd_offset"}
MODE_USES: dict[str, tuple[str, bool, set[str]]] = {
    "gz-sim-joint-controller-system": ("use_force_commands", True, PID_TAGS),
    "gz-sim-joint-position-controller-system": (
        "use_velocity_commands",
        False,
        PID_TAGS - {"cmd_max"},  # with velocity commands, cmd_max bounds the speed
    ),
}
"""Tags a gz-sim system uses only in one of its modes: (the mode's flag, the flag's value in
which the tags are used, the tags). In the other mode gz-sim ignores them, and so does twin."""


def drive_notes(key: str, params: Params, initial: float = 0.0) -> tuple[str, ...]:
    """The report notes of one drive plugin: its approximations, then each given tag twin does
    not use (ROS publishing tags named as such; a tag the system ignores in its mode, as such)."""
    notes = list(APPROXIMATED.get(key, ()))
    used = USED.get(key, set())
    flag, reads_when, mode_tags = MODE_USES.get(key, ("", True, set()))
    idle = mode_tags if flag and params.flag(False, flag) != reads_when else set()
    for tag in params.given():
        if tag in idle:
            when = "with" if reads_when else "without"
            notes.append(f"<{tag}>: gz-sim uses it only {when} {flag}; unused here, as there")
            continue
        if tag in used:
            continue
        if any(word in tag.lower() for word in ROS_TOPICS):
            notes.append(f"<{tag}>: {ROS_NOTE}")
        elif tag.startswith("initial_"):
            notes.append(f"<{tag}>{initial:g}: not applied at spawn; send it with twin command")
        else:
            notes.append(f"<{tag}>: not used by twin")
    return tuple(notes)
