"""Joint commands (position, velocity, effort) and timed pushes.

Joint commands reuse the entity's motor actuator (one per actuated joint, `ctrlrange` = ±effort
or a Gazebo PID's output range, converter contract). Effort mode keeps it a motor. Position and
velocity modes turn it into a servo *inside MuJoCo* by rewriting its gain, bias, force range and
dynamics: a plain motor (every converted robot's, and an MJCF `<motor>`) tracks a reference in
its activation (`twin_cli.world.servos`: ramps, PI); an actuator with its own bias or dynamics
(an MJCF `<position>`, a rotor's lag) a PD on ctrl (force = kp·(target − q) − kv·q̇). Either way
it runs in C at every step with no Python in the hot path, and the implicit integrator integrates
the kv term implicitly. Commands are rewritten into each new model after a recompile, since
compiling restores the spec's motor.

A multicopter rotor's joint actuator (converters.gazebo.multicopter) also sets, per command, its
thrust and drag actuators (`<actuator>:thrust`, `:drag_x`, `:drag_y`) and the motor lag.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from converters.mjcf.export_servos import PID_OFFSET_SUFFIX
from twin_cli.world import native_servos, servos, sleeping, velocity_motors

MODES = ("position", "velocity", "effort")
ROTOR_PARTS = (":drag_x", ":drag_y")  # besides ":thrust"
VELOCITY_BAND = 0.01  # fraction of the velocity limit over which Gazebo's rule fades the effort
_AFFINE = mujoco.mjtBias.mjBIAS_AFFINE
_NONE = mujoco.mjtBias.mjBIAS_NONE
_FIXED = mujoco.mjtGain.mjGAIN_FIXED
_INTEGRATOR = mujoco.mjtDyn.mjDYN_INTEGRATOR
_NO_DYN = mujoco.mjtDyn.mjDYN_NONE
_FOLLOW = mujoco.mjtDyn.mjDYN_FILTEREXACT  # a tag velocity PID's activation (native_servos)


@dataclass(frozen=True)
class JointCommand:
    """A joint target held until replaced or reset.

    Attributes:
        actuator: full actuator name ("<entity>/<joint>'s motor").
        mode: "position" | "velocity" | "effort".
        target: target [rad, m, rad/s, m/s, N m or N].
        kp: stiffness [N m/rad or N/m] (position mode); kv: damping [N m s/rad or N s/m].
        effort: the joint's effort limit [N m or N] (inf when unlimited).
        velocity_limit: the joint's velocity limit [rad/s or m/s] (inf when none).
        feedforward: velocity the position servo's damping tracks [rad/s or m/s] (trajectories).
        rule: where the gains came from (`twin joints` shows it).
        native: run by the model's own servo law, its ctrl the target
            (`twin_cli.world.native_servos`).
    """

    actuator: str
    mode: str
    target: float
    kp: float
    kv: float
    effort: float
    velocity_limit: float = math.inf
    feedforward: float = 0.0
    rule: str = ""
    native: bool = False


def effort_limit(model: mujoco.MjModel, actuator: int) -> float:
    """The most force [N m or N] the motor can apply at its joint (inf when unlimited): its
    force range, and a motor's control range (a servo's or a plugin's holds targets)."""
    gear = abs(model.actuator_gear[actuator][0]) or 1.0
    limits = []
    motor = model.actuator_biastype[actuator] == _NONE and model.actuator_plugin[actuator] < 0
    if model.actuator_ctrllimited[actuator] and motor:
        limits.append(np.max(np.abs(model.actuator_ctrlrange[actuator])) * gear)
    if model.actuator_forcelimited[actuator]:
        shifted = model.actuator_forcerange[actuator] + pid_offset(model, actuator)
        limits.append(np.max(np.abs(shifted)) * gear)
    return float(min(limits)) if limits else math.inf


def effort_range(model: mujoco.MjModel, actuator: int) -> tuple[float, float]:
    """The force range [N m or N] the motor can apply at its joint, each side for itself (a
    Gazebo PID's [cmd_min, cmd_max] need not be symmetric); ±inf where a side is unbounded."""
    gear = model.actuator_gear[actuator][0] or 1.0
    low, high = -math.inf, math.inf
    motor = model.actuator_biastype[actuator] == _NONE and model.actuator_plugin[actuator] < 0
    if model.actuator_ctrllimited[actuator] and motor:  # a plugin's ctrl is its target
        low, high = sorted(float(v) * gear for v in model.actuator_ctrlrange[actuator])
    if model.actuator_forcelimited[actuator]:
        shifted = model.actuator_forcerange[actuator] + pid_offset(model, actuator)
        f_low, f_high = sorted(float(v) * gear for v in shifted)
        low, high = max(low, f_low), min(high, f_high)
    return low, high


def pid_offset(model: mujoco.MjModel, actuator: int) -> float:
    """The constant force [N m or N] pushed beside a PID plugin actuator (a gz-sim PID's
    `cmd_offset`, `converters.mjcf.export_servos`), whose own force range is the PID's output
    range less it; 0 for other actuators."""
    if model.actuator_plugin[actuator] < 0:
        return 0.0
    name = model.actuator(actuator).name + PID_OFFSET_SUFFIX
    push = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
    return float(model.actuator_biasprm[push, 0]) if push >= 0 else 0.0


def servo_gains(mode: str, effort: float, inertia: float, timestep: float) -> tuple[float, float]:
    """PD gains (kp, kv) of a joint without control record or velocity limit (see joint_control)."""
    from twin_cli.world.joint_control import JointLimits, servo_rule

    kp, kv, _ = servo_rule(mode, JointLimits(), effort, inertia, timestep, 0.0)
    return kp, kv


def clip_target(model: mujoco.MjModel, joint: int, mode: str, value: float, effort: float) -> float:
    """The target clipped to the joint's range (position) or effort limit (effort)."""
    if mode == "position" and model.jnt_limited[joint]:
        low, high = model.jnt_range[joint]
        return float(min(max(value, low), high))
    if mode == "effort" and math.isfinite(effort):
        return float(min(max(value, -effort), effort))
    return float(value)


def apply_command(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    a: int,
    cmd: JointCommand,
    law: native_servos.Law | None = None,
) -> None:
    """Writes `cmd` into actuator `a` of `model` (gains, bias, force range) and `data.ctrl`.

    A command in the mode of the actuator's own servo (`law`, `cmd.native`) writes that law
    back and the target as ctrl, nothing else; a velocity of 0 on a joint whose own servo is a
    position servo is the joint's friction (`native_servos.hold`). Otherwise everything runs
    inside mj_step, with no Python per step:
    - position: force = kp·(target − q) + kv·(feedforward − q̇), within ±effort;
    - velocity: force = kv·(target − q̇), within ±effort;
    - effort u with a velocity limit v: Gazebo zeroes the effort while |q̇| > v in u's direction
      (Joint::CheckAndTruncateForce). Here the actuator is a velocity servo towards sign(u)·v
      with a gain reaching full effort within VELOCITY_BAND·v, and force range
      [min(0, u), max(0, u)]: force = u while q̇ ≤ v·(1 − VELOCITY_BAND), falls linearly to 0 at
      v and stays 0 beyond (the servo's pull reverses sign and the range clips it to 0).
      The implicit integrator integrates the gain's velocity term implicitly, so it is stable at
      any gain.
    """
    sleeping.wake_actuated(model, data, (a,))  # a sleeping robot must feel its new command
    cmd = _run_velocity_motor(model, data, a, cmd)
    if law is not None and cmd.native:
        native_servos.restore(model, a, law)
        data.ctrl[a] = cmd.target
        return
    if law is not None and servos.kind(cmd) == servos.HOLD:
        native_servos.hold(model, a, law, cmd.effort)
        data.ctrl[a] = 0.0
        return
    if law is not None:
        native_servos.lift(model, a, law)
    own_dynamics = model.actuator_dyntype[a] in (_INTEGRATOR, _FOLLOW)
    if own_dynamics and not servos.has_reference(model, a):
        model.actuator_dyntype[a] = _NO_DYN  # a model's own servo in another mode: ctrl alone
        model.actuator_actlimited[a] = 0
    gear = abs(model.actuator_gear[a][0]) or 1.0
    limit = cmd.effort / gear
    model.actuator_gaintype[a] = _FIXED
    model.actuator_gainprm[a, :3] = 0.0
    model.actuator_biasprm[a, :3] = 0.0
    model.actuator_ctrllimited[a] = 0
    model.actuator_forcelimited[a] = int(math.isfinite(limit))
    model.actuator_forcerange[a] = (-limit, limit) if math.isfinite(limit) else (0.0, 0.0)
    reference = servos.has_reference(model, a)
    if cmd.mode == "effort":
        if reference:
            servos.release(model, a)
        _apply_effort(model, data, a, cmd, gear, on_bias=reference)
        return
    if reference:
        servos.apply(model, data, a, cmd)
        return
    model.actuator_biastype[a] = _AFFINE
    if cmd.mode == "position":
        model.actuator_gainprm[a, 0] = cmd.kp / gear
        model.actuator_biasprm[a, 0] = cmd.kv * cmd.feedforward / gear
        model.actuator_biasprm[a, 1] = -cmd.kp / gear
    else:
        model.actuator_gainprm[a, 0] = cmd.kv / gear
    model.actuator_biasprm[a, 2] = -cmd.kv / gear
    data.ctrl[a] = cmd.target
    _apply_rotor(model, data, a, cmd)


def _run_velocity_motor(
    model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand
) -> JointCommand:
    """A joint with a velocity motor (`twin_cli.world.velocity_motors`): a velocity command
    engages it and leaves the joint's own motor at zero effort (the command returned); any other
    command disengages it and is returned unchanged."""
    rotor = velocity_motors.rotor_of(model, a)
    if rotor is None:
        return cmd
    if cmd.mode != "velocity":
        velocity_motors.disengage(model, data, rotor)
        return cmd
    velocity_motors.engage(model, data, rotor, cmd.target, cmd.effort)
    return replace(cmd, mode="effort", target=0.0, velocity_limit=math.inf, native=False)


def _apply_rotor(model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand) -> None:
    """A rotor speed ω [rad/s] (clamped at the rotor's maximum) as thrust ctrl ω|ω| and drag
    ctrl |ω|; the lag is timeConstantUp when ω|ω| rises above the thrust's activation, else
    timeConstantDown (kept in dynprm[1:3]). A no-op for other actuators."""
    name = model.actuator(a).name
    thrust = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name + ":thrust")
    if thrust < 0 or cmd.mode != "velocity":
        return
    omega = min(max(cmd.target, -cmd.velocity_limit), cmd.velocity_limit)
    push = omega * abs(omega)
    rising = push > data.act[model.actuator_actadr[thrust]]
    tau = float(model.actuator_dynprm[thrust, 1 if rising else 2])
    parts = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name + p) for p in ROTOR_PARTS]
    for part in (a, thrust, *(p for p in parts if p >= 0)):
        model.actuator_dynprm[part, 0] = tau
        data.ctrl[part] = abs(omega)
    data.ctrl[a] = omega
    data.ctrl[thrust] = push


def _apply_effort(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    a: int,
    cmd: JointCommand,
    gear: float,
    *,
    on_bias: bool = False,
) -> None:
    """Effort u as a motor (ctrl = u), or under Gazebo's velocity rule. `on_bias`: the actuator's
    input is its reference activation (`twin_cli.world.servos`), so the force is written as bias
    terms alone (gain 0) and ctrl keeps u for whoever reads it."""
    u, v = cmd.target / gear, cmd.velocity_limit
    if not math.isfinite(v):
        if on_bias:
            model.actuator_biastype[a] = _AFFINE
            model.actuator_biasprm[a, 0] = u
        else:
            model.actuator_gainprm[a, 0] = 1.0
            model.actuator_biastype[a] = _NONE
        data.ctrl[a] = u
        return
    full = abs(cmd.target)  # the band is VELOCITY_BAND·v wide whatever the effort
    gain = max(full, 1e-9) / (VELOCITY_BAND * v) / gear
    model.actuator_biastype[a] = _AFFINE
    model.actuator_biasprm[a, 2] = -gain
    model.actuator_forcelimited[a] = 1
    model.actuator_forcerange[a] = (min(0.0, u), max(0.0, u))
    if on_bias:
        model.actuator_biasprm[a, 0] = gain * math.copysign(v, u)
        data.ctrl[a] = u
        return
    model.actuator_gainprm[a, 0] = gain
    data.ctrl[a] = math.copysign(v, u)


@dataclass(frozen=True)
class Push:
    """A wrench on a body for a number of steps.

    Attributes:
        body: full body name; wrench: (fx, fy, fz [N], tx, ty, tz [N m]) in the world frame,
        at the body's centre of mass; end_step: world iteration at which it stops.
    """

    body: str
    wrench: tuple[float, ...]
    end_step: int


def apply_pushes(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    pushes: list[Push],
    bodies: set[str],
    perturbation: Mapping[str, Sequence[float]] | None = None,
) -> None:
    """Sets `xfrc_applied` of `bodies` to the sum of the active pushes on each.

    `perturbation` (body name → wrench, a viewer's mouse drag) is added on top: the engine owns
    `xfrc_applied`, and pushes and the drag are kept apart so that neither erases the other.
    """
    extra = perturbation or {}
    for body in bodies:
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
        if b < 0:
            continue
        wrenches = [p.wrench for p in pushes if p.body == body]
        if body in extra:
            wrenches.append(tuple(extra[body]))
        data.xfrc_applied[b] = np.sum(wrenches or [np.zeros(6)], axis=0)
