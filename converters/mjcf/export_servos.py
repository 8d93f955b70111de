"""The exported robot's joints that its tags command by position or velocity get servos.

In a twin World a motor is one actuator whose law follows the command's mode
(`twin_cli.world.servos`). A MuJoCo user of the exported file has only `ctrl`. Where the robot's
own tags (ros2_control interfaces, transmissions, a drive plugin) command a joint by position or
by velocity, that user expects what Gazebo's controller does: a servo bounded by the effort limit.
A raw torque within ±effort means nothing there and breaks the model: 10 N m on a turtlebot3
wheel (2e-5 kg m²) spins it past 1e5 rad/s within a second of random `ctrl`, and MuJoCo diverges.

So each such joint is written as MuJoCo's own position or integrated-velocity actuator:
  - `ctrl` is the target (position within the joint's range, velocity within its limit), the
    force stays within ±effort (`forcerange`), as Menagerie's models do;
  - a position servo is stiff and damped so that a move at the effort limit stops on target
    (`servo_gains`);
  - every joint whose tags offer velocity gets Gazebo's velocity motor (`velocity_motors`: a
    rotor and a friction tendon bounded by the effort, or by its UNBOUNDED_EFFORT where the
    joint has no effort limit, as Gazebo's velocity command then has none); it stores nothing, where
    an integral servo paid a stall back as a burst. Its torque motor stays for effort commands,
    and a position-first joint keeps its position servo beside it. A tag's velocity PID
    (ros2_control's `velocity_pid`, gz-sim JointController's force commands) is that
    controller's own law instead; a velocity-first joint the motor cannot serve (no inertia
    along its axis to scale a rotor on) is MuJoCo's `intvelocity`, kv = I/h on the joint's
    reflected inertia I at the home posture, the integral kp = kv²/(4·INTEGRAL_MARGIN·I);
  - on a fixed base, the position servos carry the weight of the bodies they hold through
    MuJoCo's gravity compensation, within the effort limit (`export_gravcomp`);
  - a gz-sim position PID with an integral is MuJoCo's `mujoco.pid` actuator plugin, its
    `cmd_offset` a constant-force actuator beside it (`_add_offsets`);
  - the `home` keyframe's ctrl holds the home posture.
Joints with no control tags (Gazebo leaves them passive), and effort interfaces, keep their
torque motor. The control record keeps the motor each servo replaced (`EXPORTED`) and the
compensation it added, and a joint's velocity motor its effort (`VELOCITY_MOTOR`). A World gives
a description the same servos when it spawns it and runs them by ctrl
(`twin_cli.world.native_servos`), so the file and the world are one model.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from converters.control_text import CONTROL_TEXT, PID_INTEGRAL, PID_OFFSET
from converters.mjcf.export_gravcomp import GRAVCOMP, compensate
from converters.mjcf.servo_gains import largest_inertia, position_gains, reflected_inertia
from converters.mjcf.velocity_motors import Motor, add_velocity_motors
from converters.mjcf.world_options import TIMESTEP_S

INTEGRAL_MARGIN = 8.0
"""A velocity servo's kp is its integral gain, kv²/(4·INTEGRAL_MARGIN·I_c) on the inertia I_c it
carries (a World's servos, `twin_cli.world.servos`, and this file's, on the joint's own inertia).
A velocity step makes it store the lag of the damping term and give it back as overshoot, about
1/(4·INTEGRAL_MARGIN) of the step (3 %) when the carried inertia is right, less when it is
overestimated; the integral then settles a load in about 4·INTEGRAL_MARGIN·I_c/kv."""

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

    import mujoco

EXPORTED = "exported_motor"  # record key: the torque motor a servo replaced in the file
VELOCITY_MOTOR = "velocity_motor"  # record key: the joint's velocity motor (`velocity_motors`)
MOTOR_JOINTS = ("hinge", "slide")  # joint kinds a velocity motor's rotor can copy
UNTAGGED_SOURCES = ("default", "passive")  # records of joints no control tag commands
FOLLOW_TAU = 1e-12  # [s] time constant of an activation that follows ctrl within one step
SERVO_MODES = ("position", "velocity")
PID_PLUGIN = "mujoco.pid"  # MuJoCo's PID actuator plugin, for a gz-sim PID with an integral
PID_INSTANCE = ":pid"  # suffix of the plugin instance's name, after its actuator's
PID_OFFSET_SUFFIX = ":offset"  # a PID plugin's cmd_offset: its tendon and actuator, after the joint
HOME_KEY = "home"


def export_servos(spec: mujoco.MjSpec, timestep: float = TIMESTEP_S) -> dict[str, str]:
    """Rewrites `spec`'s tagged position and velocity joint motors as servos (module doc), and
    gives each joint whose tags offer velocity commands Gazebo's velocity motor
    (`converters.mjcf.velocity_motors`): a joint whose first mode is velocity keeps its torque
    motor for effort commands and runs its velocity commands on the motor.

    Returns:
        Each joint given a servo or a velocity motor, with its first mode.
    """
    text = spec.text(CONTROL_TEXT)
    if text is None:
        return {}
    records = json.loads(text.data)
    chosen = [
        (i, a, records[a.target]) for i, a in enumerate(spec.actuators) if _servoed(a, records)
    ]
    driven = [a for a in spec.actuators if _offers_velocity(spec, a, records)]
    offsets = _effort_offsets(records)  # constant forces beside PID plugins join these below
    if not chosen and not driven:
        _add_offsets(spec, offsets)
        return {}
    servoed: dict[str, str] = {}
    held: dict[str, tuple[float, float]] = {}  # each position servo's force range
    inertia, home, model = _home_inertia(spec)
    key = _home_key(spec)
    ctrl = np.array(key.ctrl, dtype=float) if key is not None else np.zeros(0)
    if key is not None and len(ctrl) != len(spec.actuators):
        ctrl = np.zeros(len(spec.actuators))
    motors = _motors(driven, records, inertia)
    for i, actuator, record in chosen:
        joint = actuator.target
        if not inertia.get(joint, (0.0, 0.0))[0] > 0.0 or (
            joint in motors and motors[joint].engaged
        ):
            continue  # nothing to tune a servo on, or a velocity motor: the torque motor stays
        record[EXPORTED] = {
            "ctrlrange": [float(v) for v in actuator.ctrlrange],
            "ctrllimited": int(actuator.ctrllimited),
            "forcerange": [float(v) for v in actuator.forcerange],
            "forcelimited": int(actuator.forcelimited),
            "actlimited": int(actuator.actlimited),
            "actrange": [float(v) for v in actuator.actrange],
        }
        _to_servo(spec, actuator, record, inertia[joint], timestep)
        if actuator.plugin.active and record.get(PID_OFFSET):
            offsets[joint] = float(record[PID_OFFSET])
        servoed[joint] = record["modes"][0]
        if record["modes"][0] == "position":
            if tag_pid(record.get("pid", {}), "position") is None:  # a Gazebo PID: no help
                held[joint] = _force_range(actuator)
            if key is not None:
                ctrl[i] = home[joint]
    if key is not None:
        key.ctrl = ctrl
    for joint, changed in compensate(spec, held).items():
        records[joint][EXPORTED][GRAVCOMP] = changed
    for joint, motor in motors.items():
        effort = motor.effort if np.isfinite(motor.effort) else None  # None: no effort limit
        records[joint][VELOCITY_MOTOR] = {"effort": effort, "engaged": motor.engaged}
        servoed.setdefault(joint, records[joint]["modes"][0])
    if motors:  # a robot without velocity joints runs none of it
        add_velocity_motors(spec, list(motors.values()), model, timestep)
    _add_offsets(spec, offsets)
    text.data = json.dumps(records)
    return servoed


def tag_pid(pids: Mapping[str, Sequence[float]], mode: str) -> tuple | None:
    """The (p, i, d) gains a joint's tags give `mode`'s PID (`pids`: a control record's "pid"),
    or None. A velocity PID without a p gain is none: gazebo_ros2_control then sets the joint's
    velocity, as for a plain velocity interface, rather than run a loop that pushes nothing."""
    pid = pids.get(mode)
    if not pid or (mode == "velocity" and float(pid[0]) <= 0.0):
        return None
    return tuple(pid)


def tag_servo_gains(
    pid: Sequence[float], inertia: float, timestep: float, effort: float
) -> tuple[float, float]:
    """(kp, kv) of a position servo a tag's PID sets: its p and its d, as Gazebo's PID applies
    them (no damping added: an underdamped tag rings in twin as in Gazebo). The one change: with
    an effort limit kv stays at most I/h, since MuJoCo integrates the damping of a clamped
    force explicitly and more than I/h per step then overshoots the speed it brakes."""
    kp, kd = float(pid[0]), max(float(pid[2]), 0.0)
    return kp, min(kd, inertia / timestep) if np.isfinite(effort) else kd


def _offers_velocity(spec: mujoco.MjSpec, actuator: mujoco.MjsActuator, records: dict) -> bool:
    """Whether a joint motor (gear 1, no dynamics or bias) drives a hinge or slide whose tags
    offer velocity commands and give no velocity PID: ros2_control's `velocity_pid` and gz-sim's
    JointController with force commands close a PID on the speed error, a force law, not the
    joint motor's constraint."""
    import mujoco

    record = records.get(actuator.target)
    if record is None:
        return False
    joint = spec.joint(actuator.target)
    return (
        joint is not None
        and joint.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
        and actuator.trntype == mujoco.mjtTrn.mjTRN_JOINT
        and float(actuator.gear[0]) == 1.0
        and actuator.dyntype == mujoco.mjtDyn.mjDYN_NONE
        and actuator.biastype == mujoco.mjtBias.mjBIAS_NONE
        and record.get("source") not in UNTAGGED_SOURCES
        and "velocity" in record.get("modes", ())
        and tag_pid(record.get("pid", {}), "velocity") is None  # a tag PID: a force loop
        and VELOCITY_MOTOR not in record
    )


def _motors(
    driven: list[mujoco.MjsActuator], records: dict, inertia: dict[str, tuple[float, float]]
) -> dict[str, Motor]:
    """The velocity motor of each of `driven`'s joints that has an inertia to scale its rotor."""
    import mujoco

    motors = {}
    for actuator in driven:
        joint, record = actuator.target, records[actuator.target]
        own = inertia.get(joint, (0.0, 0.0))[0]
        effort = (
            float(np.max(np.abs(actuator.ctrlrange)))
            if actuator.ctrllimited == mujoco.mjtLimited.mjLIMITED_TRUE
            else float("inf")
        )
        if own > 0.0 and effort > 0.0:
            speed = record.get("velocity_limit")
            speed = float(speed) if speed is not None and speed > 0 else float("inf")
            engaged = record["modes"][0] == "velocity"
            motors[joint] = Motor(joint, effort, own, speed, engaged)
    return motors


def _servoed(actuator: mujoco.MjsActuator, records: dict) -> bool:
    import mujoco

    record = records.get(actuator.target)
    return (
        record is not None
        and actuator.trntype == mujoco.mjtTrn.mjTRN_JOINT
        and float(actuator.gear[0]) == 1.0
        and actuator.dyntype == mujoco.mjtDyn.mjDYN_NONE
        and actuator.biastype == mujoco.mjtBias.mjBIAS_NONE
        and record.get("source") not in UNTAGGED_SOURCES
        and bool(record.get("modes"))
        and record["modes"][0] in SERVO_MODES
    )


def _to_servo(
    spec: mujoco.MjSpec,
    actuator: mujoco.MjsActuator,
    record: dict,
    inertias: tuple[float, float],
    timestep: float,
) -> None:
    """One motor (gear 1) → MuJoCo's position or velocity actuator, its effort as the bound.

    The tags' own PID gains (ros2_control `pos_kp`/`pos_kd`, a gz-sim controller's p and d)
    replace the inertia rule, as in the world (docs/control.md).
    """
    import mujoco

    mode = record["modes"][0]
    inertia, largest = inertias
    kv = inertia / timestep
    limited = actuator.ctrllimited == mujoco.mjtLimited.mjLIMITED_TRUE
    effort = float(np.max(np.abs(actuator.ctrlrange))) if limited else np.inf
    if limited:
        actuator.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.forcerange = np.asarray(actuator.ctrlrange, dtype=float)
    low, high = _target_range(spec, actuator.target, record)
    actuator.ctrllimited = (
        mujoco.mjtLimited.mjLIMITED_TRUE if np.isfinite(high) else mujoco.mjtLimited.mjLIMITED_FALSE
    )
    actuator.ctrlrange = np.array([low, high]) if np.isfinite(high) else np.zeros(2)
    pid = tag_pid(record.get("pid", {}), mode)
    if mode == "position":
        if pid:  # the controller's own p and d, as the world runs them (`tag_servo_gains`)
            kp, kv = tag_servo_gains(pid, inertia, timestep, effort)
        else:
            speed = record.get("velocity_limit")
            kp, kv = position_gains(inertia, largest, effort, speed, high - low, timestep)
        if pid and PID_INTEGRAL in record:
            _to_pid_plugin(spec, actuator, (kp, float(pid[1]), kv), record[PID_INTEGRAL])
            if limited:  # offset and PID are clamped together (`_add_offsets`)
                actuator.forcerange = actuator.forcerange - float(record.get(PID_OFFSET, 0.0))
            return
        actuator.set_to_position(kp=kp, kv=kv)
        if pid:
            actuator.biasprm[0] = float(record.get(PID_OFFSET, 0.0))
    elif pid:
        _to_velocity_pid(actuator, pid)
        actuator.biasprm[0] = float(record.get(PID_OFFSET, 0.0))
    else:
        _to_intvelocity(spec, actuator, inertia, kv)


def _to_pid_plugin(
    spec: mujoco.MjSpec, actuator: mujoco.MjsActuator, gains: tuple, limit: float | None
) -> None:
    """A gz-sim position PID with an integral: MuJoCo's own `mujoco.pid` actuator plugin, force
    = kp·(ctrl − q) − kd·q̇ + ki·∫(ctrl − q)dt, the integral term within ±`limit` (unbounded for
    None) and the whole within the actuator's `forcerange`, as gz-math clamps its output. The
    integral is the actuator's one activation, so the file, the world and a saved world carry
    it; its damping is explicit, as Gazebo's is (`tag_servo_gains` keeps it at most I/h)."""
    kp, ki, kd = gains
    spec.activate_plugin(PID_PLUGIN)
    instance = spec.add_plugin(name=f"{actuator.name}{PID_INSTANCE}", plugin_name=PID_PLUGIN)
    instance.active = True
    config = {"kp": f"{kp!r}", "ki": f"{ki!r}", "kd": f"{kd!r}"}
    if limit is not None:
        config["imax"] = f"{float(limit)!r}"
    instance.config = config
    actuator.set_to_motor()  # the plugin computes the force; gain and bias are not read
    actuator.plugin = instance
    actuator.actdim = 1


def _effort_offsets(records: Mapping[str, dict]) -> dict[str, float]:
    """The constant force [N m or N] of each joint a Gazebo PID with no gains leaves on its
    torque motor (a JointTrajectoryController joint whose gains are all 0 still pushes its
    `cmd_offset`), by joint."""
    return {
        joint: float(record[PID_OFFSET])
        for joint, record in records.items()
        if isinstance(record, dict)
        and record.get(PID_OFFSET)
        and (record.get("modes") or [None])[0] == "effort"
    }


def _add_offsets(spec: mujoco.MjSpec, offsets: Mapping[str, float]) -> None:
    """Each gz-sim PID plugin's `cmd_offset` (`offsets`, by joint [N m or N]; also a limp
    joint's, `_effort_offsets`): MuJoCo's pid actuator has no constant force, so a second
    actuator pushes it, through a one-joint tendon (the joint keeps one joint actuator).
    gz-math clamps offset and PID together to [cmd_min, cmd_max], which the joint's effort
    limit may narrow; the plugin's force range is that range less the offset (`_to_servo`), so
    the sum is clamped alike. Keyframes get ctrl 0 for the new actuators (they read no ctrl)."""
    import mujoco

    have = {t.name for t in spec.tendons}  # a spec exported before keeps its pushes
    offsets = {j: v for j, v in offsets.items() if f"{j}{PID_OFFSET_SUFFIX}" not in have}
    before = len(spec.actuators)
    for joint, offset in offsets.items():
        tendon = spec.add_tendon(name=f"{joint}{PID_OFFSET_SUFFIX}")
        tendon.wrap_joint(joint, 1.0)
        push = spec.add_actuator(name=tendon.name, target=tendon.name)
        push.trntype = mujoco.mjtTrn.mjTRN_TENDON
        push.gainprm[0] = 0.0  # force = biasprm[0], whatever ctrl holds
        push.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        push.biasprm[0] = offset
    for key in spec.keys if offsets else ():
        ctrl = np.array(key.ctrl, dtype=float)
        if len(ctrl) == before:
            key.ctrl = np.concatenate([ctrl, np.zeros(len(offsets))])


def _to_intvelocity(
    spec: mujoco.MjSpec, actuator: mujoco.MjsActuator, inertia: float, kv: float
) -> None:
    """A velocity servo with an integral: MuJoCo's `intvelocity`, whose activation is the
    position the velocity command integrates to and which a position servo tracks, so `ctrl`
    0 holds a loaded joint where it is (a parked base on a slope) and a loaded joint keeps its
    speed. kv = I/h, the integral kp = kv²/(4·INTEGRAL_MARGIN·I), as a World's velocity servo on
    the joint's own inertia. A limited joint's reference stays in its range."""
    import mujoco

    actuator.set_to_intvelocity(kp=kv**2 / (4 * INTEGRAL_MARGIN * inertia), kv=kv)
    joint = spec.joint(actuator.target)
    if joint is not None and joint.limited == mujoco.mjtLimited.mjLIMITED_TRUE:
        actuator.actlimited = mujoco.mjtLimited.mjLIMITED_TRUE
        actuator.actrange = np.asarray(joint.range, dtype=float)


def _to_velocity_pid(actuator: mujoco.MjsActuator, pid: tuple) -> None:
    """ros2_control's `velocity_pid` and gz-sim's JointController with force commands push
    p·(ω* − ω) (+ i·∫(ω* − ω)) within the effort limit. The p term is MuJoCo's velocity law,
    force = p·(ctrl − q̇), written as a general actuator whose one activation follows ctrl within
    the step (`filterexact`, τ FOLLOW_TAU, `actearly`): the force of a `velocity` actuator to the
    last bit, and the activation slot such a joint had as an `intvelocity` before, so that world
    files saved then load unchanged. The integral and derivative gains are reported, not run:
    one actuator cannot add ∫ctrl to p·ctrl, and the `intvelocity` (kp = i, kv = p) that tried
    took p/i seconds to answer a step (5 s at p 0.5, i 0.1), where the PID answers at once."""
    import mujoco

    p = float(pid[0])
    actuator.set_to_velocity(kv=p)
    actuator.dyntype = mujoco.mjtDyn.mjDYN_FILTEREXACT
    actuator.dynprm = np.array([FOLLOW_TAU] + [0.0] * (len(actuator.dynprm) - 1))
    actuator.actearly = True


def _force_range(actuator: mujoco.MjsActuator) -> tuple[float, float]:
    """A servo's force range [N m or N]: its `forcerange` (asymmetric where a PID's output
    range is), unbounded without one."""
    import mujoco

    if actuator.forcelimited != mujoco.mjtLimited.mjLIMITED_TRUE:
        return (-np.inf, np.inf)
    return (float(actuator.forcerange[0]), float(actuator.forcerange[1]))


def _target_range(spec: mujoco.MjSpec, joint_name: str, record: dict) -> tuple[float, float]:
    """A position servo's targets: the joint's range; a velocity servo's: ±its velocity limit."""
    import mujoco

    if record["modes"][0] == "position":
        joint = spec.joint(joint_name)
        if joint is not None and joint.limited == mujoco.mjtLimited.mjLIMITED_TRUE:
            return float(joint.range[0]), float(joint.range[1])
        return -np.inf, np.inf
    limit = record.get("velocity_limit")
    if limit is not None and np.isfinite(limit) and limit > 0:
        return -float(limit), float(limit)
    return -np.inf, np.inf


def _home_inertia(
    spec: mujoco.MjSpec,
) -> tuple[dict[str, tuple[float, float]], dict[str, float], mujoco.MjModel]:
    """Each joint's reflected inertia (`servo_gains.reflected_inertia`: the other joints held,
    a floating base free) at the home posture and the largest over its range
    (`servo_gains.largest_inertia`) [kg m² or kg], its home position, and the compiled model."""
    import mujoco

    model = spec.copy().compile()
    data = mujoco.MjData(model)
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, HOME_KEY)
    if key >= 0:
        data.qpos[:] = model.key_qpos[key]
    mujoco.mj_forward(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)  # MuJoCo 4 signature: (m, d, dst)
    largest = largest_inertia(model)
    reflected = reflected_inertia(model, full)
    inertia, home = {}, {}
    for j in range(model.njnt):
        dof, adr = model.jnt_dofadr[j], model.jnt_qposadr[j]
        at_home = float(reflected[dof])
        inertia[model.joint(j).name] = (at_home, max(at_home, float(largest[dof])))
        home[model.joint(j).name] = float(data.qpos[adr])
    return inertia, home, model


def _home_key(spec: mujoco.MjSpec) -> mujoco.MjsKey | None:
    return next((k for k in spec.keys if k.name == HOME_KEY), None)
