"""Each drive plugin's parameters → its typed record, under the plugin's own names and defaults.

One reader per plugin, chosen from a `{plugin: reader}` table (`READERS`) by the normalised
filename (`plugin_key`): gazebo_ros' ROS 1 and ROS 2 spellings, gz-sim systems under their
current and old (ignition) names. The defaults are the ones each plugin's `Load`/`Configure`
uses, so a robot whose file leaves a tag out drives as it does in Gazebo.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass

from converters.description.gazebo import Blob
from converters.errors import GazeboTagError
from converters.gazebo.drive_records import (
    DEFAULT_ACCELERATION,
    DEFAULT_DIAMETER,
    DEFAULT_RATE,
    DEFAULT_SEPARATION,
    DEFAULT_TORQUE,
    EVERY_STEP,
    UNBOUNDED,
    AckermannDrive,
    DiffDrive,
    DriveRecord,
    HolonomicDrive,
    JointDrive,
    TricycleDrive,
)
from converters.gazebo.gz_names import gz_names
from converters.gazebo.plugin_params import Params
from converters.gazebo.trajectory_controller import read_joint_trajectory_controller
from converters.gazebo.wheel_geometry import WheelGeometry


@dataclass(frozen=True)
class ReadContext:
    """What a reader needs besides the plugin: the file, the model's name and its canonical
    (base) link (gz-sim's default frame names use them) and the robot's measured wheels."""

    source: str
    model: str
    geometry: WheelGeometry | None
    base_link: str = "base_link"


def plugin_key(blob: Blob) -> str:
    """The plugin's filename without path, `lib`, `.so` and version, with gz-sim's old
    `ignition-gazebo` prefix made `gz-sim` (`libignition-gazebo6-diff-drive-system.so` →
    `gz-sim-diff-drive-system`)."""
    filename = (blob.kind or "").rsplit("/", 1)[-1].removeprefix("lib").removesuffix(".so")
    filename = filename.replace("ignition-gazebo", "gz-sim")
    return re.sub(r"^gz-sim\d*-", "gz-sim-", filename)


def _required(p: Params, tags: tuple[str, ...], default: str | None = None) -> tuple[str, ...]:
    names = p.names(*tags)
    if names:
        return names
    if default is not None:
        return (default,)
    raise GazeboTagError(p.source, "", f"plugin/{tags[0]}", "", "a wheel joint name")


def read_ros_diff_drive(p: Params, blob: Blob, ctx: ReadContext) -> DiffDrive:
    """gazebo_ros_diff_drive (ROS 2 names, then ROS 1's)."""
    return DiffDrive(
        name=blob.name or "diff_drive",
        where=blob.where,
        left_joints=_required(p, ("left_joint", "leftJoint")),
        right_joints=_required(p, ("right_joint", "rightJoint")),
        wheel_separation=p.number(DEFAULT_SEPARATION, "wheel_separation", "wheelSeparation"),
        wheel_diameter=p.number(DEFAULT_DIAMETER, "wheel_diameter", "wheelDiameter"),
        max_wheel_torque=p.number(DEFAULT_TORQUE, "max_wheel_torque", "wheelTorque"),
        max_wheel_acceleration=p.number(
            DEFAULT_ACCELERATION, "max_wheel_acceleration", "wheelAcceleration"
        ),
        odometry_source=p.odometry_source("world", "odometry_source", "odometrySource"),
        update_rate=p.number(DEFAULT_RATE, "update_rate", "updateRate"),
        odometry_frame=p.text("odom", "odometry_frame", "odometryFrame"),
        robot_base_frame=p.text("base_footprint", "robot_base_frame", "robotBaseFrame"),
        odom_topic=p.ros_topic("odom", "odometryTopic", "robotNamespace"),
    )


def read_skid_steer(p: Params, blob: Blob, ctx: ReadContext) -> DiffDrive:
    """gazebo_ros_skid_steer_drive (ROS 1): four named wheels, driven as two diff-drive sides;
    its odometry is the model's world pose."""
    return DiffDrive(
        name=blob.name or "skid_steer_drive",
        where=blob.where,
        left_joints=_required(p, ("leftFrontJoint",), "left_front_joint")
        + _required(p, ("leftRearJoint",), "left_rear_joint"),
        right_joints=_required(p, ("rightFrontJoint",), "right_front_joint")
        + _required(p, ("rightRearJoint",), "right_rear_joint"),
        wheel_separation=p.number(0.4, "wheelSeparation"),
        wheel_diameter=p.number(DEFAULT_DIAMETER, "wheelDiameter"),
        max_wheel_torque=p.number(DEFAULT_TORQUE, "torque"),
        update_rate=p.number(DEFAULT_RATE, "updateRate"),
        family="gazebo_ros_skid_steer_drive",
        odometry_frame=p.text("odom", "odometryFrame"),
        robot_base_frame=p.text("base_footprint", "robotBaseFrame"),
        odom_topic=p.ros_topic("odom", "odometryTopic", "robotNamespace"),
    )


def gz_twist_acceleration(p: Params) -> tuple[float, float, float, float]:
    """gz-sim's DiffDrive acceleration bounds, as its SpeedLimiters take them: (min, max) of the
    linear [m/s²], then of the angular [rad/s²] command's change, signed (a deceleration bound
    is negative); `min_acceleration`/`max_acceleration` set both, the `_linear_`/`_angular_`
    tags win, and a bound no tag sets is none (±inf): with `max_linear_acceleration` alone the
    base speeds up at that rate and stops at once."""
    return (
        p.number(-math.inf, "min_linear_acceleration", "min_acceleration", signed=True),
        p.number(math.inf, "max_linear_acceleration", "max_acceleration", signed=True),
        p.number(-math.inf, "min_angular_acceleration", "min_acceleration", signed=True),
        p.number(math.inf, "max_angular_acceleration", "max_acceleration", signed=True),
    )


def read_gz_diff_drive(p: Params, blob: Blob, ctx: ReadContext) -> DiffDrive:
    """gz-sim DiffDrive: velocity commands on every left/right joint, odometry from the
    wheels' positions, speed and acceleration limits on the body twist."""
    return DiffDrive(
        name=blob.name or "DiffDrive",
        where=blob.where,
        left_joints=_required(p, ("left_joint",)),
        right_joints=_required(p, ("right_joint",)),
        wheel_separation=p.number(1.0, "wheel_separation"),
        wheel_diameter=2.0 * p.number(0.2, "wheel_radius"),
        max_wheel_torque=math.inf,
        max_wheel_acceleration=0.0,
        twist_acceleration=gz_twist_acceleration(p),
        odometry_source="encoder",
        update_rate=EVERY_STEP,
        family="gz_diff_drive",
        odometry_frame=p.text(f"{ctx.model}/odom", "frame_id"),
        robot_base_frame=p.text(f"{ctx.model}/{ctx.base_link}", "child_frame_id"),
        max_linear_velocity=p.number(math.inf, "max_linear_velocity", "max_velocity"),
        max_angular_velocity=p.number(math.inf, "max_angular_velocity", "max_velocity"),
        min_velocities=(  # a bound no tag sets is none, as in its SpeedLimiters
            p.number(-math.inf, "min_linear_velocity", "min_velocity", signed=True),
            p.number(-math.inf, "min_angular_velocity", "min_velocity", signed=True),
        ),
        gz=gz_names(p, ctx.base_link),
    )


def read_ros_ackermann(p: Params, blob: Blob, ctx: ReadContext) -> AckermannDrive:
    """gazebo_ros_ackermann_drive: rear wheels driven, front wheels steered; like the plugin,
    the wheel base, track and radius are measured on the model (its collisions)."""
    joints = {
        tag: p.text(tag, tag)
        for tag in (
            "front_left_joint",
            "front_right_joint",
            "rear_left_joint",
            "rear_right_joint",
            "left_steering_joint",
            "right_steering_joint",
        )
    }
    if ctx.geometry is None:
        raise GazeboTagError(ctx.source, "", "plugin", blob.kind or "", "a plugin of a model")
    centre = {tag: ctx.geometry.centre(joint, tag) for tag, joint in joints.items()}
    front = (centre["front_left_joint"] + centre["front_right_joint"]) / 2
    rear = (centre["rear_left_joint"] + centre["rear_right_joint"]) / 2
    track = float(_distance(centre["front_left_joint"], centre["front_right_joint"]))
    return AckermannDrive(
        name=blob.name or "ackermann_drive",
        where=blob.where,
        left_joints=(joints["rear_left_joint"],),
        right_joints=(joints["rear_right_joint"],),
        left_steering_joints=(joints["left_steering_joint"],),
        right_steering_joints=(joints["right_steering_joint"],),
        wheel_base=float(_distance(front, rear)),
        wheel_separation=track,
        kingpin_width=track,
        wheel_radius=ctx.geometry.radius(joints["rear_right_joint"], "rear_right_joint"),
        steering_limit=p.number(0.6, "max_steer"),
        max_velocity=p.number(20.0, "max_speed"),
        update_rate=p.number(DEFAULT_RATE, "update_rate"),
        odometry_frame=p.text("odom", "odometry_frame"),
        robot_base_frame=p.text("base_footprint", "robot_base_frame"),
    )


def read_gz_ackermann(p: Params, blob: Blob, ctx: ReadContext) -> AckermannDrive:
    """gz-sim AckermannSteering: cmd_vel's angular.z is a yaw rate, turned into a turning
    radius; wheel speeds follow its partial differential; odometry from the wheels."""
    return AckermannDrive(
        name=blob.name or "AckermannSteering",
        where=blob.where,
        left_joints=_required(p, ("left_joint",)),
        right_joints=_required(p, ("right_joint",)),
        left_steering_joints=_required(p, ("left_steering_joint",)),
        right_steering_joints=_required(p, ("right_steering_joint",)),
        wheel_base=p.number(1.0, "wheel_base"),
        wheel_separation=p.number(1.0, "wheel_separation"),
        kingpin_width=p.number(0.8, "kingpin_width"),
        wheel_radius=p.number(0.2, "wheel_radius"),
        steering_limit=p.number(0.5, "steering_limit"),
        twist_bounds=(  # one pair of SpeedLimiters, the same bounds on v and on ω
            p.number(-math.inf, "min_velocity", signed=True),
            p.number(math.inf, "max_velocity", signed=True),
            p.number(-math.inf, "min_acceleration", signed=True),
            p.number(math.inf, "max_acceleration", signed=True),
        ),
        steering_gain=p.number(1.0, "steer_p_gain", signed=True),
        update_rate=EVERY_STEP,
        odometry_source="encoder",
        odometry_frame=p.text(f"{ctx.model}/odom", "frame_id"),
        robot_base_frame=p.text(f"{ctx.model}/{ctx.base_link}", "child_frame_id"),
        family="gz_ackermann_steering",
        angular_is_steering=False,
        gz=gz_names(p, ctx.base_link),
    )


def read_tricycle(p: Params, blob: Blob, ctx: ReadContext) -> TricycleDrive:
    """gazebo_ros_tricycle_drive; the wheel base (steered wheel to the encoder axle) is
    measured on the model."""
    steering = p.text("front_steering_joint", "steering_joint")
    wheel = p.text("front_wheel_joint", "actuated_wheel_joint")
    left = p.text("left_wheel_joint", "encoder_wheel_left_joint")
    right = p.text("right_wheel_joint", "encoder_wheel_right_joint")
    if ctx.geometry is None:
        raise GazeboTagError(ctx.source, "", "plugin", blob.kind or "", "a plugin of a model")
    g = ctx.geometry
    axle = g.centre(left, "encoder_wheel_left_joint") + g.centre(right, "encoder_wheel_right_joint")
    base = float(_distance(g.centre(wheel, "actuated_wheel_joint"), axle / 2))
    accel = p.number(0.0, "max_wheel_acceleration")
    return TricycleDrive(
        name=blob.name or "tricycle_drive",
        where=blob.where,
        steering_joint=steering,
        actuated_wheel_joint=wheel,
        encoder_left_joint=left,
        encoder_right_joint=right,
        actuated_wheel_diameter=p.number(0.15, "actuated_wheel_diameter"),
        encoder_wheel_diameter=p.number(0.15, "encoder_wheel_diameter"),
        wheel_separation=p.number(0.5, "wheel_separation"),
        wheel_base=base,
        max_wheel_torque=p.number(0.15, "max_wheel_torque"),
        max_wheel_acceleration=accel,
        max_wheel_deceleration=p.number(accel, "max_wheel_deceleration"),
        max_steering_speed=p.number(0.0, "max_steering_speed"),
        update_rate=p.number(DEFAULT_RATE, "update_rate"),
        odometry_source=p.odometry_source("world", "odometry_source"),
        odometry_frame=p.text("odom", "odometry_frame"),
        robot_base_frame=p.text("base_link", "robot_base_frame"),
    )


PLANAR_MOVE_RATE = 20.0  # [Hz] gazebo_ros_planar_move's (ROS 2) default update_rate


def read_planar_move(p: Params, blob: Blob, ctx: ReadContext) -> HolonomicDrive:
    """gazebo_ros_planar_move (ROS 2 names, then ROS 1's). ROS 2's sets the base's velocity at
    its `update_rate` (default 20 Hz); ROS 1's at every world update (its `odometryRate` only
    paces the odometry it publishes), so a plugin with ROS 1's tags and no `update_rate` runs
    every step."""
    ros1 = p.names("odometryRate", "odometryFrame", "robotBaseFrame", "commandTopic") != ()
    return HolonomicDrive(
        name=blob.name or "planar_move",
        where=blob.where,
        update_rate=p.number(EVERY_STEP if ros1 else PLANAR_MOVE_RATE, "update_rate"),
        odometry_frame=p.text("odom", "odometry_frame", "odometryFrame"),
        robot_base_frame=p.text("base_footprint", "robot_base_frame", "robotBaseFrame"),
    )


def read_gz_mecanum(p: Params, blob: Blob, ctx: ReadContext) -> HolonomicDrive:
    """gz-sim MecanumDrive: the base's twist; its wheels are spun at their kinematic speeds."""
    wheels = p.names("front_left_joint", "front_right_joint", "back_left_joint", "back_right_joint")
    return HolonomicDrive(
        name=blob.name or "MecanumDrive",
        where=blob.where,
        family="gz_mecanum_drive",
        update_rate=EVERY_STEP,
        wheel_joints_named=wheels,
        wheel_radius=p.number(0.2, "wheel_radius"),
        wheel_separation=p.number(1.0, "wheel_separation"),
        wheelbase=p.number(1.0, "wheelbase"),
        max_linear_velocity=p.number(math.inf, "max_velocity"),
        odometry_frame=p.text(f"{ctx.model}/odom", "frame_id"),
        robot_base_frame=p.text(f"{ctx.model}/{ctx.base_link}", "child_frame_id"),
        gz=gz_names(p, ctx.base_link),
        notes=(
            "rollers: their 45° friction (fdir1, mu2) has no MuJoCo counterpart on a cylinder; "
            "the base is driven by its twist as planar move, the wheels spun to match",
        ),
    )


def read_gz_velocity_control(p: Params, blob: Blob, ctx: ReadContext) -> HolonomicDrive:
    """gz-sim VelocityControl: the model's twist in its own frame, set at every step, from
    `initial_linear`/`initial_angular` until a first command on `<topic>` (default
    `/model/<model>/cmd_vel`). twin runs its planar part (x, y, yaw) as planar move's."""
    linear, angular = p.vector3("initial_linear"), p.vector3("initial_angular")
    ignored = [n for n, v in (("linear z", linear[2]), ("angular x", angular[0])) if v]
    ignored += ["angular y"] if angular[1] else []
    notes = [
        "the planar twist (x, y, yaw) of its canonical link's origin, through three velocity "
        "servos at the centre of mass; gz-sim sets all six velocities (z, roll and pitch are "
        "left to the physics here) and publishes no odometry (twin's is the world pose)"
    ]
    if ignored:
        notes.append(f"initial {', '.join(ignored)}: not run (twin drives the planar twist)")
    return HolonomicDrive(
        name=blob.name or "VelocityControl",
        where=blob.where,
        family="gz_velocity_control",
        update_rate=EVERY_STEP,
        initial_twist=(linear[0], linear[1], angular[2]),
        odometry_frame=f"{ctx.model}/odom",
        robot_base_frame=f"{ctx.model}/{ctx.base_link}",
        gz=gz_names(p, ctx.base_link),
        notes=tuple(notes),
    )


POSITION_PID_NOTE = (
    "its PID as MuJoCo's pid actuator: kp = p_gain, kd = d_gain on the joint's speed, ki = "
    "i_gain (0.1 unless given) with the integral term within ±i_max, the force within "
    "[cmd_min, cmd_max]; the derivative's kick when the target jumps is not run"
)
ASYMMETRIC_INTEGRAL_NOTE = (
    "i_min {low:g} and i_max {high:g}: the integral term within ±{bound:g} (MuJoCo's pid "
    "actuator bounds it symmetrically)"
)

SET_SPEED_NOTE = (
    "with use_velocity_commands, a stiff position servo (gz-sim sets the speed that reaches the "
    "target in one step, at most cmd_max when given; that speed bound is not run)"
)


def read_joint_controller(p: Params, blob: Blob, ctx: ReadContext) -> JointDrive:
    """gz-sim JointController: a velocity on its joints (set directly, or through its PID on
    the joint force with `use_force_commands`)."""
    force = p.flag(False, "use_force_commands")
    gains = (p.number(1.0, "p_gain"), p.number(0.0, "i_gain"), p.number(0.0, "d_gain"))
    return JointDrive(
        name=blob.name or "JointController",
        where=blob.where,
        joints=_required(p, ("joint_name",)),
        mode="velocity",
        pid=gains if force else None,
        force_range=_pid_output(p) if force else UNBOUNDED,
        force_offset=p.number(0.0, "cmd_offset", signed=True) if force else 0.0,
        initial=p.number(0.0, "initial_velocity", signed=True),
    )


def read_joint_position_controller(p: Params, blob: Blob, ctx: ReadContext) -> JointDrive:
    """gz-sim JointPositionController: a PID on the joint force (or on its velocity with
    `use_velocity_commands`) towards a position."""
    velocity = p.flag(False, "use_velocity_commands")
    gains = (p.number(1.0, "p_gain"), p.number(0.1, "i_gain"), p.number(0.01, "d_gain"))
    offset = 0.0 if velocity else p.number(0.0, "cmd_offset", signed=True)
    limit, notes = _integral_limit(p) if gains[1] else (None, ())
    return JointDrive(
        name=blob.name or "JointPositionController",
        where=blob.where,
        joints=_required(p, ("joint_name",)),
        mode="position",
        pid=None if velocity else gains,
        force_range=UNBOUNDED if velocity else _pid_output(p),
        force_offset=offset,
        integral_limit=limit,
        initial=p.number(0.0, "initial_position", signed=True),
        family="gz_joint_position_controller",
        notes=(SET_SPEED_NOTE,) if velocity else (POSITION_PID_NOTE, *notes),
    )


def read_apply_joint_force(p: Params, blob: Blob, ctx: ReadContext) -> JointDrive:
    """gz-sim ApplyJointForce: the force its `/model/<model>/joint/<joint>/cmd_force` carries,
    on `joint_name`, held until the next one (none before): an effort command's torque."""
    return JointDrive(
        name=blob.name or "ApplyJointForce",
        where=blob.where,
        joints=_required(p, ("joint_name",)),
        mode="effort",
        pid=None,
        force_range=UNBOUNDED,
        family="gz_apply_joint_force",
    )


def _integral_limit(p: Params) -> tuple[float | None, tuple[str, ...]]:
    """The bound [N m or N] on gz-math's integral term: it clamps the term to [i_min, i_max]
    (defaults ∓1), or not at all when i_max < i_min. MuJoCo's pid actuator bounds it by one
    magnitude, the larger, and a note says so when the two differ."""
    low, high = p.number(-1.0, "i_min", signed=True), p.number(1.0, "i_max", signed=True)
    if high < low:
        return None, ()
    bound = max(abs(low), abs(high))
    if low == -high:
        return bound, ()
    return bound, (ASYMMETRIC_INTEGRAL_NOTE.format(low=low, high=high, bound=bound),)


def _pid_output(p: Params) -> tuple[float, float]:
    """The force range [N m or N] gz-math's PID clamps its output to: [`cmd_min`, `cmd_max`],
    each defaulting to ∓1000 on its own (so a lone `cmd_max` 2 leaves pushes down to -1000), and
    no clamp at all when `cmd_max` < `cmd_min`.

    Raises:
        GazeboTagError: `cmd_min` equals `cmd_max` (a constant force, not a controller).
    """
    low, high = p.number(-1000.0, "cmd_min", signed=True), p.number(1000.0, "cmd_max", signed=True)
    if low == high:  # gz-math would push this one force whatever the error: refused
        raise GazeboTagError(p.source, "", "plugin/cmd_min", f"{low:g}", "a number below cmd_max")
    return (low, high) if high > low else UNBOUNDED


def _distance(a: object, b: object) -> float:
    import numpy as np

    return float(np.linalg.norm(np.asarray(a) - np.asarray(b)))


Reader = Callable[[Params, Blob, ReadContext], DriveRecord]
READERS: dict[str, Reader] = {
    "gazebo_ros_diff_drive": read_ros_diff_drive,
    "gazebo_ros_skid_steer_drive": read_skid_steer,
    "gazebo_ros_ackermann_drive": read_ros_ackermann,
    "gazebo_ros_tricycle_drive": read_tricycle,
    "gazebo_ros_planar_move": read_planar_move,
    "gz-sim-diff-drive-system": read_gz_diff_drive,
    "gz-sim-ackermann-steering-system": read_gz_ackermann,
    "gz-sim-mecanum-drive-system": read_gz_mecanum,
    "gz-sim-velocity-control-system": read_gz_velocity_control,
    "gz-sim-joint-controller-system": read_joint_controller,
    "gz-sim-joint-position-controller-system": read_joint_position_controller,
    "gz-sim-joint-trajectory-controller-system": read_joint_trajectory_controller,
    "gz-sim-apply-joint-force-system": read_apply_joint_force,
}
