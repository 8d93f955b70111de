"""The drive plugins twin runs, typed: one record per kinematic family, each with its plugin's
own parameter names and defaults.

- `DiffDrive`: gazebo_ros diff drive and skid steer, gz-sim DiffDrive, and vendor plugins read as
  a differential drive (unicycle kinematics).
- `AckermannDrive`: gazebo_ros Ackermann drive and gz-sim AckermannSteering (bicycle kinematics,
  each front wheel steered on its own Ackermann angle).
- `TricycleDrive`: gazebo_ros tricycle drive (a steered, driven front wheel; bicycle kinematics).
- `HolonomicDrive`: gazebo_ros planar move and gz-sim MecanumDrive (the base's planar twist).
- `JointDrive`: gz-sim JointController (a velocity on joints) and JointPositionController.
- `TrajectoryDrive`: gz-sim JointTrajectoryController (per-joint PIDs, a trajectory topic).

Units are SI: [m], [m/s], [m/s²], [rad], [N m], [Hz]; `math.inf` is "no limit".
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields, is_dataclass
from typing import Any

from converters.gazebo.gz_names import GzNames

# Defaults of gazebo_ros_diff_drive (ROS 2 `Load`, ROS 1 `getParameter` defaults).
DEFAULT_SEPARATION = 0.34  # [m]
DEFAULT_DIAMETER = 0.15  # [m]
DEFAULT_TORQUE = 5.0  # [N m]
DEFAULT_ACCELERATION = 0.0  # [m/s²] at the wheel rim; 0 = unlimited
DEFAULT_RATE = 100.0  # [Hz]
EVERY_STEP = 0.0
"""[Hz] the update rate of a plugin that acts at every physics step: gz-sim's DiffDrive,
AckermannSteering and MecanumDrive set their joints' velocities in every `PreUpdate` (their
`odom_publish_frequency` only throttles the odometry messages), ROS 1's planar move sets the
model's velocity at every world update."""
UNBOUNDED = (-math.inf, math.inf)  # a force range without a bound


def _plain(value: Any) -> Any:
    if is_dataclass(value) and not isinstance(value, type):
        return asdict(value)
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None  # JSON has no infinity: null is "no limit"
    return value


class _Record:
    """JSON for the server's drive listing and replies (inf limits become null)."""

    def to_dict(self) -> dict[str, Any]:
        """Plain values for JSON; `kind` names the record's family."""
        out = {f.name: _plain(getattr(self, f.name)) for f in fields(self)}  # type: ignore[arg-type]
        return {"kind": type(self).__name__, **out}


@dataclass(frozen=True)
class DiffDrive(_Record):
    """A differential drive, typed.

    Attributes:
        name: the plugin's name attribute; where: file and element, for messages.
        left_joints, right_joints: wheel joint names (several pairs: skid steer, ROS 2, gz-sim).
        wheel_separation [m], wheel_diameter [m], max_wheel_torque [N m] (inf: unbounded, as
        gz-sim's velocity commands), max_wheel_acceleration [m/s² at the rim; 0 = unlimited, as
        in the plugin's code], odometry_source: "world" or "encoder"; update_rate [Hz] (0 = every
        step). family: the plugin (`gazebo_ros_diff_drive`, `gazebo_ros_skid_steer_drive`,
        `gz_diff_drive`, `vendor:<filename>`); odometry_frame, robot_base_frame: the odometry's
        frame names; max_linear_velocity [m/s], max_angular_velocity [rad/s] (gz-sim's limits);
        min_velocities: the lowest (signed) linear [m/s] and angular [rad/s] command, where the
        plugin bounds them apart from the highest (gz-sim's `min_*_velocity`, unset: none; a
        controller's `min_velocity`); None: the negated maxima;
        twist_acceleration: the bounds (min, max) on the commanded forward speed's change
        [m/s²] and then on the yaw rate's [rad/s²], ±inf where none, for a plugin that limits
        the body twist before it turns it into wheel speeds (gz-sim's SpeedLimiter); None: the
        wheels' rims ramp at max_wheel_acceleration instead (gazebo_ros' diff drive); these
        bounds hold while the last command is forward (> 0);
        reverse_acceleration: the same bounds while the last command is backward (< 0), from 0
        its min with twist_acceleration's max (ros2_controllers' rate limiter since Jazzy);
        None: twist_acceleration whatever the direction;
        command_timeout [s]: how long a ROS cmd_vel holds (diff_drive_controller's
        cmd_vel_timeout; 0: until the next); odom_topic: the odometry's ROS topic as the plugin
        names it (relative: under the entity's name); notes: what was approximated or ignored,
        one entry per tag.
    """

    name: str
    where: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    wheel_separation: float = DEFAULT_SEPARATION
    wheel_diameter: float = DEFAULT_DIAMETER
    max_wheel_torque: float = DEFAULT_TORQUE
    max_wheel_acceleration: float = DEFAULT_ACCELERATION
    odometry_source: str = "world"
    update_rate: float = DEFAULT_RATE
    family: str = "gazebo_ros_diff_drive"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    max_linear_velocity: float = math.inf
    max_angular_velocity: float = math.inf
    min_velocities: tuple[float, float] | None = None
    twist_acceleration: tuple[float, float, float, float] | None = None
    reverse_acceleration: tuple[float, float, float, float] | None = None
    command_timeout: float = 0.0
    odom_topic: str = "odom"
    cmd_vel_topic: str = ""  # the ROS topic its plugin takes cmd_vel on ("": none named)
    gz: GzNames | None = None  # a gz-sim system's names (None: not a gz-sim system)
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """Every joint the drive turns."""
        return self.left_joints + self.right_joints


@dataclass(frozen=True)
class AckermannDrive(_Record):
    """A car-like base: driven wheels on one axle, the front wheels steered.

    Attributes:
        left_joints, right_joints: driven wheel joints. left_steering_joints,
        right_steering_joints: steering joints. wheel_base [m] (axle to axle), wheel_separation
        [m] (driven wheels' track), kingpin_width [m] (steering pivots' spacing), wheel_radius
        [m], steering_limit [rad], max_velocity [m/s], max_acceleration [m/s²] (0 = none),
        max_wheel_torque [N m] (inf = unbounded), update_rate [Hz], odometry_source,
        odometry_frame, robot_base_frame, family, notes: as `DiffDrive`. angular_is_steering:
        the plugin reads cmd_vel's angular.z as the steering angle (gazebo_ros) rather than a
        yaw rate (gz-sim). twist_bounds: gz-sim's speed limiters, the same for the forward
        speed and the yaw rate: (min, max) of the command [m/s or rad/s] and (min, max) of its
        change [m/s² or rad/s²], signed, ±inf where no tag sets one (None: `max_velocity` and
        `max_acceleration` bound the speed alone, as gazebo_ros; with twist_bounds those two
        fields are unused). steering_gain: gz-sim's `steer_p_gain` [1/s]: each update the
        steering joints are commanded the speed gain·(angle − joint angle) (None: position
        targets, as gazebo_ros' PID holds them).
    """

    name: str
    where: str
    left_joints: tuple[str, ...]
    right_joints: tuple[str, ...]
    left_steering_joints: tuple[str, ...]
    right_steering_joints: tuple[str, ...]
    wheel_base: float
    wheel_separation: float
    kingpin_width: float
    wheel_radius: float
    steering_limit: float
    max_velocity: float = math.inf
    max_acceleration: float = 0.0
    max_wheel_torque: float = math.inf
    update_rate: float = DEFAULT_RATE
    odometry_source: str = "world"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    family: str = "gazebo_ros_ackermann_drive"
    angular_is_steering: bool = True
    twist_bounds: tuple[float, float, float, float] | None = None
    steering_gain: float | None = None
    cmd_vel_topic: str = ""  # the ROS topic its plugin takes cmd_vel on ("": none named)
    gz: GzNames | None = None  # a gz-sim system's names (None: not a gz-sim system)
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """Every joint the drive turns or steers."""
        return (
            self.left_joints
            + self.right_joints
            + self.left_steering_joints
            + self.right_steering_joints
        )


@dataclass(frozen=True)
class TricycleDrive(_Record):
    """gazebo_ros_tricycle_drive: one steered and driven wheel, two encoder wheels behind.

    Attributes:
        steering_joint, actuated_wheel_joint, encoder_left_joint, encoder_right_joint: joints.
        actuated_wheel_diameter [m], encoder_wheel_diameter [m], wheel_separation [m] (encoder
        wheels), wheel_base [m] (the steered wheel to the encoder axle, measured from the model),
        max_wheel_torque [N m], max_wheel_acceleration, max_wheel_deceleration [rad/s² of the
        wheel, as the plugin compares joint speeds], max_steering_speed [rad/s] (0 = none),
        update_rate [Hz], odometry_source, odometry_frame, robot_base_frame, family, notes.
    """

    name: str
    where: str
    steering_joint: str
    actuated_wheel_joint: str
    encoder_left_joint: str
    encoder_right_joint: str
    actuated_wheel_diameter: float
    encoder_wheel_diameter: float
    wheel_separation: float
    wheel_base: float
    max_wheel_torque: float = 0.15
    max_wheel_acceleration: float = 0.0
    max_wheel_deceleration: float = 0.0
    max_steering_speed: float = 0.0
    update_rate: float = DEFAULT_RATE
    odometry_source: str = "world"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_link"
    family: str = "gazebo_ros_tricycle_drive"
    angular_is_steering: bool = True
    cmd_vel_topic: str = ""  # the ROS topic its plugin takes cmd_vel on ("": none named)
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """The joints the drive turns or steers (the encoder wheels roll freely)."""
        return (self.actuated_wheel_joint, self.steering_joint)


@dataclass(frozen=True)
class HolonomicDrive(_Record):
    """A base driven by its planar twist (vx, vy, ωz in its own frame).

    Attributes:
        family: `gazebo_ros_planar_move`, `gz_mecanum_drive` or `gz_velocity_control`;
        update_rate [Hz]; wheel_joints_named: the mecanum wheels (spun at their kinematic
        speeds), else (); wheel_radius, wheel_separation, wheelbase [m] (mecanum);
        max_linear_velocity [m/s], max_angular_velocity [rad/s]; initial_twist: (vx [m/s],
        vy [m/s], ωz [rad/s]) it drives from load until a first command (gz-sim
        VelocityControl's `initial_linear`/`initial_angular`); odometry_frame,
        robot_base_frame, notes.
    """

    name: str
    where: str
    family: str = "gazebo_ros_planar_move"
    update_rate: float = DEFAULT_RATE
    wheel_joints_named: tuple[str, ...] = ()
    wheel_radius: float = 0.0
    wheel_separation: float = 0.0
    wheelbase: float = 0.0
    max_linear_velocity: float = math.inf
    max_angular_velocity: float = math.inf
    initial_twist: tuple[float, float, float] = (0.0, 0.0, 0.0)
    odometry_source: str = "world"
    odometry_frame: str = "odom"
    robot_base_frame: str = "base_footprint"
    cmd_vel_topic: str = ""  # the ROS topic its plugin takes cmd_vel on ("": none named)
    gz: GzNames | None = None  # a gz-sim system's names (None: not a gz-sim system)
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """The mecanum wheels (none for planar move)."""
        return self.wheel_joints_named


@dataclass(frozen=True)
class JointDrive(_Record):
    """gz-sim's JointController (velocity), JointPositionController (position) or
    ApplyJointForce (effort) on joints.

    Attributes:
        joints: the joints it commands; mode: "velocity", "position" or "effort"; pid: (p, i,
        d) when the system runs its own PID on the joint's force, else None (it sets the joint's
        velocity, or its force as commanded);
        force_range: (low, high) [N m or N] its force stays in; force_offset [N m or N] its PID
        adds (`cmd_offset`); integral_limit: [N m or N] the bound on its PID's integral term
        (None: unbounded); initial: the system's initial command, notes.
    """

    name: str
    where: str
    joints: tuple[str, ...]
    mode: str
    pid: tuple[float, float, float] | None = None
    force_range: tuple[float, float] = UNBOUNDED
    force_offset: float = 0.0
    integral_limit: float | None = None
    initial: float = 0.0
    family: str = "gz_joint_controller"
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """The joints it commands."""
        return self.joints


@dataclass(frozen=True)
class TrajectoryDrive(_Record):
    """gz-sim's JointTrajectoryController: a position PID and a velocity PID on each joint,
    summed into the joint's force, that step through the trajectories sent on its topic.

    Attributes:
        joints: the joints it controls, in order (every 1-axis joint when none is named);
        initial_positions: [rad or m] per joint, what the PIDs hold before any trajectory;
        pids: per joint (p, i, d) for twin's position servo: the position PID's p, no i (not
        used), its d plus the velocity PID's p (both act on the joint's speed), or None when
        they are 0 (gz-sim applies no force; twin's own gains); force_ranges: (low, high)
        [N m or N] per joint; force_offsets: [N m or N] per joint, the sum of its two PIDs'
        `cmd_offset`; topic, progress_topic: where gz-sim takes trajectories and
        reports progress.
    """

    name: str
    where: str
    joints: tuple[str, ...]
    initial_positions: tuple[float, ...]
    pids: tuple[tuple[float, float, float] | None, ...]
    force_ranges: tuple[tuple[float, float], ...]
    topic: str
    progress_topic: str
    force_offsets: tuple[float, ...] = ()
    family: str = "gz_joint_trajectory_controller"
    notes: tuple[str, ...] = ()

    def wheel_joints(self) -> tuple[str, ...]:
        """The joints it commands."""
        return self.joints


BaseDrive = DiffDrive | AckermannDrive | TricycleDrive | HolonomicDrive
DriveRecord = BaseDrive | JointDrive | TrajectoryDrive


def held_from_load(plugins: tuple) -> dict[str, tuple[str, float]]:
    """What Gazebo's drive plugins command from their first step: joint → (mode, target).

    A drive plugin sends its wheels the speeds of its last twist on every update, from load, with
    the plugin's torque: zero until a first command, so a parked base holds on a slope (a
    turtlebot3 whose wheels roll free runs 16 m down a 5° slope in 10 s). Steering joints are
    held at the straight-ahead angle 0, and gz-sim's JointController sends its `initial`
    velocity. Holonomic bases (their planar servo already holds a zero twist) and position
    controllers are not listed. Targets are [rad/s or m/s] (velocity) and [rad] (position).
    """
    held: dict[str, tuple[str, float]] = {}
    for plugin in plugins:
        if isinstance(plugin, DiffDrive):
            held.update(dict.fromkeys(plugin.wheel_joints(), ("velocity", 0.0)))
        elif isinstance(plugin, AckermannDrive):
            held.update(dict.fromkeys(plugin.left_joints + plugin.right_joints, ("velocity", 0.0)))
            steering = plugin.left_steering_joints + plugin.right_steering_joints
            held.update(dict.fromkeys(steering, ("position", 0.0)))
        elif isinstance(plugin, TricycleDrive):
            held[plugin.actuated_wheel_joint] = ("velocity", 0.0)
            held[plugin.steering_joint] = ("position", 0.0)
        elif isinstance(plugin, JointDrive) and plugin.mode == "velocity":
            held.update(dict.fromkeys(plugin.joints, ("velocity", plugin.initial)))
    return held
