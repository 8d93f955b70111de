"""Motors for the drives twin runs: each wheel and steering joint a drive plugin names gets one,
and a holonomic base gets a planar velocity servo on its root link.

Gazebo's drive plugins command their joints directly (a joint velocity with `fmax`, a force, a
position) whatever `<transmission>` or `<ros2_control>` says, so their joints need a motor even
without those tags. A joint whose tags gave it a motor keeps it (its tags decide its modes); a
new one, or the untagged torque motor of a joint with an effort limit, offers only the mode the
plugin uses, with the plugin's gains (a gz-sim joint controller's PID), bounded by the plugin's
torque (by the joint's limit when the plugin sets velocities directly, as gz-sim's systems do;
unbounded without one). Left untagged, such a wheel ran on the world's generic velocity servo,
whose integral takes seconds to carry its robot: a turtlebot3 gz-sim model turned 59 % short.

Planar move (and MecanumDrive, whose rollers MuJoCo cannot model) drives the base's planar twist.
Gazebo's planar move overwrites the model's velocity every step; twin gives the root link three
site actuators (`<plugin>:vx`, `:vy` along the link's own x and y, `:wz` about its z), each a
velocity servo force = kv·(target − velocity) in the link's frame, computed by MuJoCo at every
step with no Python: a constant body-frame command needs no writes while it holds, where a servo
on the free joint (world-frame x, y) would need new targets as the heading turns, and an
`xfrc_applied` PD would act only at the controller's rate. The site sits at the robot's centre
of mass, so the force does not pitch the base (at the link origin, below it, a 0.3 m/s step
flipped a box on four feet). kv = M/PLANAR_TAU (I_zz/PLANAR_TAU for the yaw), integrated
implicitly by the implicit integrator, so the twist is reached within a few steps and a
friction load μ·M·g leaves only μ·g·PLANAR_TAU of error (0.1 mm/s at μ = 1; a parked base
on 5° creeps 0.26 mm in 30 s, 2.6 mm at 1e-4 s).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from converters.control_text import (
    PID_INTEGRAL,
    PID_OFFSET,
    control_records,
    set_control_record,
)
from converters.description.robot import MODEL_SITE
from converters.errors import PluginJointError
from converters.gazebo.drive_records import (
    UNBOUNDED,
    AckermannDrive,
    DiffDrive,
    DriveRecord,
    HolonomicDrive,
    JointDrive,
    TrajectoryDrive,
    TricycleDrive,
)
from converters.gazebo.multicopter import Rotor, add_rotors
from converters.gazebo.trajectory_controller import HOME_KEY, start_at_initial_positions
from converters.gazebo.wheel_contact import centre_wheel_contacts
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

PLANAR_TAU = 1e-5  # [s] time constant of the planar velocity servo (implicit: any value is stable)
PLANAR_AXES = (("vx", (1, 0, 0, 0, 0, 0)), ("vy", (0, 1, 0, 0, 0, 0)), ("wz", (0, 0, 0, 0, 0, 1)))
PLANAR_SITE = "planar:{name}"


def planar_actuator(plugin: str, axis: str) -> str:
    """The name of a holonomic drive's servo along `axis` ("vx", "vy" or "wz")."""
    return f"planar:{plugin}:{axis}"


def planar_ctrl(
    drive: HolonomicDrive,
    twist: Sequence[float],
    centre: Sequence[float] | np.ndarray,
    quat: Sequence[float] | np.ndarray,
) -> tuple[float, float, float]:
    """The planar servos' ctrl for `twist` (vx, vy, ωz): the servos move the robot's centre of
    mass (their site: `centre` from the root link's origin, turned by `quat`, both in the link's
    frame). gz-sim's VelocityControl sets the velocity of its canonical link's origin, which
    differs from the centre's by ω × r; planar move and MecanumDrive set the centre's."""
    import mujoco

    vx, vy, wz = (float(v) for v in twist)
    if drive.family != "gz_velocity_control":
        return vx, vy, wz
    back = np.zeros(4)
    mujoco.mju_negQuat(back, np.asarray(quat, dtype=float))
    r = np.zeros(3)
    mujoco.mju_rotVecQuat(r, np.asarray(centre, dtype=float), back)  # r in the site's axes
    return vx - wz * float(r[1]), vy + wz * float(r[0]), wz


def planar_controls(
    model: mujoco.MjModel, entity: str, drive: HolonomicDrive, twist: Sequence[float]
) -> tuple[list[int], tuple[float, float, float]] | None:
    """The ids of `entity`'s planar servos for `drive` in a compiled world `model`, and their
    ctrl for `twist` (`planar_ctrl`, from their site); None when the model has none (a
    hand-written file)."""
    import mujoco

    actuator, site = mujoco.mjtObj.mjOBJ_ACTUATOR, mujoco.mjtObj.mjOBJ_SITE
    ids = [
        mujoco.mj_name2id(model, actuator, f"{entity}/{planar_actuator(drive.name, a)}")
        for a, _ in PLANAR_AXES
    ]
    s = mujoco.mj_name2id(model, site, f"{entity}/{PLANAR_SITE.format(name=drive.name)}")
    if min(ids) < 0 or s < 0:
        return None
    return ids, planar_ctrl(drive, twist, model.site_pos[s], model.site_quat[s])


JointMode = tuple[str, str, "tuple[float, float]", "tuple[float, float, float] | None"]


def _within(effort: float) -> tuple[float, float]:
    return (-effort, effort)


def joint_modes(record: DriveRecord) -> Sequence[JointMode]:
    """(joint, mode, force range [N m or N], pid) for each joint the drive commands."""
    if isinstance(record, DiffDrive):
        wheels = record.wheel_joints()
        return [(j, "velocity", _within(record.max_wheel_torque), None) for j in wheels]
    if isinstance(record, AckermannDrive):
        wheels = record.left_joints + record.right_joints
        steering = record.left_steering_joints + record.right_steering_joints
        # gz-sim steers by joint speed commands (`steering_gain`), gazebo_ros to an angle
        steer = "position" if record.steering_gain is None else "velocity"
        return [(j, "velocity", _within(record.max_wheel_torque), None) for j in wheels] + [
            (j, steer, _within(math.inf), None) for j in steering
        ]
    if isinstance(record, TricycleDrive):
        return [
            (record.actuated_wheel_joint, "velocity", _within(record.max_wheel_torque), None),
            (record.steering_joint, "position", _within(math.inf), None),
        ]
    if isinstance(record, JointDrive):
        return [(j, record.mode, record.force_range, record.pid) for j in record.joints]
    if isinstance(record, TrajectoryDrive):
        rows = zip(record.joints, record.force_ranges, record.pids, strict=True)
        # a limp joint: gz-sim adds a trajectory's effort after its PIDs' clamps, so unbounded
        return [
            (j, "position", f, pid) if pid else (j, "effort", UNBOUNDED, None) for j, f, pid in rows
        ]
    return []


def add_drive_motors(
    spec: mujoco.MjSpec, plugins: tuple[DriveRecord | Rotor, ...], report: Report
) -> None:
    """Motors for every drive's joints (unless they have one), planar servos for holonomic
    bases, each multicopter rotor its actuators (`converters.gazebo.multicopter.add_rotors`),
    wheels that touch the ground on their mid-plane (`converters.gazebo.wheel_contact`), and a
    report line for each approximation a drive makes.

    Raises:
        PluginJointError: a joint the plugin names is not a joint of the model.
    """
    import mujoco

    add_rotors(spec, tuple(p for p in plugins if isinstance(p, Rotor)), report)
    drives = tuple(p for p in plugins if not isinstance(p, Rotor))
    centre_wheel_contacts(spec, drives, report)
    driven = {a.target for a in spec.actuators}
    for record in plugins:
        if isinstance(record, Rotor):
            continue
        for joint, mode, force, pid in joint_modes(record):
            if spec.joint(joint) is None:
                free = mujoco.mjtJoint.mjJNT_FREE
                joints = [j.name for j in spec.joints if j.type != free]
                raise PluginJointError(report.source, record.name, "", joint, joints)
            if joint not in driven:
                _motor(spec, joint, force)
                set_control_record(spec, joint, _record(record, joint, mode, pid))
                driven.add(joint)
            elif _untagged(spec, joint):
                if isinstance(record, JointDrive | TrajectoryDrive):
                    _narrow(spec, joint, force)
                else:
                    _bound(spec, joint, force)
                set_control_record(spec, joint, _record(record, joint, mode, pid))
        if isinstance(record, HolonomicDrive):
            _planar_servos(spec, record)
        if isinstance(record, TrajectoryDrive):
            start_at_initial_positions(spec, record)
        for note in record.notes:
            report.approximated("model", f"<plugin> '{record.name}': {note}", tag="plugin")


def _untagged(spec: mujoco.MjSpec, joint: str) -> bool:
    """Whether `joint`'s motor is the builder's default (no control tag, e.g. the torque motor
    of a joint with an effort limit): the plugin that commands the joint then decides its mode
    and gains (a gz-sim joint controller's own PID), as it would for a joint without a motor."""
    return control_records(spec).get(joint, {}).get("source") == "default"


def _bound(spec: mujoco.MjSpec, joint: str, force: tuple[float, float]) -> None:
    """A wheel drive's own torque bound (gazebo_ros' `fmax`, which replaces the joint motor's
    bound in ODE) replaces the joint's effort limit on the motor it already has; a drive that
    sets velocities (unbounded here: gz-sim's) leaves the joint's limit, which Gazebo's velocity
    command obeys. Joint controllers' forces stay within the joint's limit as well (`_narrow`)."""
    import mujoco

    if not all(math.isfinite(f) for f in force):
        return
    for motor in spec.actuators:
        if motor.target == joint and motor.trntype == mujoco.mjtTrn.mjTRN_JOINT:
            motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            motor.ctrlrange = np.array(force, dtype=float)


def _narrow(spec: mujoco.MjSpec, joint: str, force: tuple[float, float]) -> None:
    """A joint controller's PID output range on a joint with its own effort limit: the force
    stays within both, as gz-sim clamps the PID's output and the physics engine then the
    joint's effort. Ranges that do not overlap (a PID that only pushes beyond the joint's
    limit) keep the joint's limit alone, both ways."""
    import mujoco

    for motor in spec.actuators:
        if motor.target == joint and motor.trntype == mujoco.mjtTrn.mjTRN_JOINT:
            limited = motor.ctrllimited == mujoco.mjtLimited.mjLIMITED_TRUE
            low, high = motor.ctrlrange if limited else (-math.inf, math.inf)
            low, high = max(float(low), force[0]), min(float(high), force[1])
            if math.isfinite(low) and math.isfinite(high) and low < high:  # else the joint's
                motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
                motor.ctrlrange = np.array([low, high])


def _motor(spec: mujoco.MjSpec, joint: str, force: tuple[float, float]) -> None:
    """The joint's motor, its torque within `force` (both ends finite) or free."""
    import mujoco

    motor = spec.add_actuator(name=joint, target=joint)
    motor.trntype = mujoco.mjtTrn.mjTRN_JOINT
    if all(math.isfinite(f) for f in force):
        motor.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        motor.ctrlrange = np.array(force, dtype=float)


def _record(drive: DriveRecord, joint: str, mode: str, pid: tuple | None) -> dict[str, Any]:
    """The plugin's joints take only the mode it commands them in; a joint or trajectory
    controller's PID offset (gz-math's `cmd_offset`, a constant force added before the clamp)
    travels along."""
    record = {
        "modes": [mode],
        "source": drive.family,
        "where": drive.where,
        "bounds": {},
        "pid": {mode: list(pid)} if pid else {},
        "velocity_limit": None,
        "plugin": None,
    }
    offset = _pid_offset(drive, joint)
    if offset and (pid or mode == "effort"):  # a limp trajectory joint's PIDs still push it
        record[PID_OFFSET] = offset
    if pid and pid[1] and isinstance(drive, JointDrive) and mode == "position":
        record[PID_INTEGRAL] = drive.integral_limit  # gz-math's integral, bounded or not
    return record


def _pid_offset(drive: DriveRecord, joint: str) -> float:
    """The constant force [N m or N] the drive's PID adds on `joint` (0 for other drives)."""
    if isinstance(drive, JointDrive):
        return drive.force_offset
    if isinstance(drive, TrajectoryDrive) and drive.force_offsets:
        return drive.force_offsets[drive.joints.index(joint)]
    return 0.0


def _planar_servos(spec: mujoco.MjSpec, drive: HolonomicDrive) -> None:
    """Three velocity servos at the robot's centre of mass on the root link (see the module
    docstring): a force there turns the base without pitching it, as a set velocity does."""
    import mujoco

    root = spec.worldbody.first_body()
    if root is None:
        return
    mass, yaw_inertia, centre = _planar_inertia(spec)
    site = root.add_site(name=PLANAR_SITE.format(name=drive.name))
    site.pos = centre
    frame = spec.site(MODEL_SITE)
    if (
        drive.family == "gz_velocity_control"
        and frame is not None
        and frame.parent.name == root.name
    ):
        site.quat = np.array(frame.quat, dtype=float)  # gz-sim turns the twist by the model's pose
    before = len(spec.actuators)
    for axis, gear in PLANAR_AXES:
        servo = spec.add_actuator(name=planar_actuator(drive.name, axis), target=site.name)
        servo.trntype = mujoco.mjtTrn.mjTRN_SITE
        servo.gear = np.array(gear, dtype=float)
        kv = (yaw_inertia if axis == "wz" else mass) / PLANAR_TAU
        servo.set_to_velocity(kv=kv)
    _start_twist(spec, before, planar_ctrl(drive, drive.initial_twist, centre, site.quat))


def _start_twist(spec: mujoco.MjSpec, before: int, twist: tuple[float, float, float]) -> None:
    """The home key's ctrl for the `before`..+3 planar servos: the twist the plugin drives from
    load (gz-sim VelocityControl's initial one; 0 for the others), so the exported file's home
    starts it as the world does (`twin_cli.world.plugin_holds`)."""
    key = next((k for k in spec.keys if k.name == HOME_KEY), None)
    if key is None or not any(twist):
        return
    ctrl = np.array(key.ctrl, dtype=float)
    if len(ctrl) not in (0, before):
        return  # a key written for other actuators: left as it is
    key.ctrl = np.concatenate([ctrl if len(ctrl) else np.zeros(before), twist])


def _planar_inertia(spec: mujoco.MjSpec) -> tuple[float, float, np.ndarray]:
    """The robot's mass [kg], its inertia about the vertical through its centre of mass
    [kg m²] and that centre [m] in the root link's frame (zero posture)."""
    import mujoco

    model = spec.copy().compile()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    centre = np.array(data.subtree_com[1])
    mass, izz = 0.0, 0.0
    for b in range(1, model.nbody):
        m = float(model.body_mass[b])
        rot = data.ximat[b].reshape(3, 3)
        inertia = rot @ np.diag(model.body_inertia[b]) @ rot.T
        offset = data.xipos[b] - centre
        mass += m
        izz += float(inertia[2, 2]) + m * float(offset[0] ** 2 + offset[1] ** 2)
    root_rot = data.xmat[1].reshape(3, 3)
    return mass, max(izz, 1e-9), root_rot.T @ (centre - data.xpos[1])
