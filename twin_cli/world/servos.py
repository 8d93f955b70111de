"""Position and velocity servos that hold their target under load, with their reference in C.

Gazebo's joint motor is a velocity constraint bounded by the effort limit: it reaches the
commanded speed in one step whenever the torque needed is within the limit. MuJoCo has no
bounded constraint an actuator can aim at a non-zero speed, and a motor's velocity feedback is
integrated implicitly only while its force stays inside `forcerange`: with kv above I/h one
clamped step carries the joint past its target and the next throws it back (a free wheel at 5 N m
swung 0 ↔ 8 rad/s every step). A plain velocity servo must therefore keep kv ≤ I/h, and then sags
under any load (a wheel at 3 rad/s with half its effort as load ran at 2.75 rad/s, or backwards
for a lighter wheel).

So every motor of a spawned robot gets one activation, a reference position r [rad or m] that
MuJoCo integrates itself (dyntype integrator, ṙ = ctrl), and the servo tracks it:

    force = kp·(r − q) + kv·(ṙ_ff − q̇),   within ±effort

- velocity v*: ctrl = v*, ṙ_ff = v*, r starts at q. kp·(r − q) = kp·∫(v* − q̇)dt is the integral
  term of a PI velocity servo: under a constant load the joint runs at v* exactly. Nothing
  bounds the integral but a limited joint's range (`actrange`): MuJoCo has no bounded integral
  an actuator can hold, so after a stall the joint catches up with r (a 0.1 N m wheel at 3 rad/s
  overloaded 1.5× for 0.5 s peaks at 43 rad/s after the release), where Gazebo's constraint
  motor would not.
- velocity 0 (HOLD): the joint's dry friction bounded by its effort, the motor pushing nothing
  (`twin_cli.world.speed_holds`): no integral, so nothing to pay back after a stop.
- position q*: r ramps from q to q* at 0.95·v_max and stops there (`actrange` clamps it); the PD
  is overdamped and tracks the ramp 2·v/ω behind, then settles
  without overshoot (the error after the ramp is (2v/ω + v·t)·e^(−ωt), never negative). A 1 rad
  move at 1 rad/s settles within 1 % in about 1.1 s. Without a velocity limit r jumps to q*.
- trajectory: the follower writes r and its speed at each update; r ramps between updates.
- a fixed-base robot's weight goes through its position servos' actuators as MuJoCo's own
  gravity compensation (`twin_cli.world.gravity_comp`), within the same effort limit.

kv = I/h on the joint's own reflected inertia I, the most damping a clamped step tolerates, and
kp critically damped on the inertia I_c the joint carries when the command arrives
(`twin_cli.world.joint_control.posture_loads`: its other joints held, and a wheel's robot through
its contacts), with INTEGRAL_MARGIN for velocity. A wheel carries its robot: tuned on the wheel
alone, a cart's wheels rang to 1.34 rad/s on a 1 rad/s command.
Everything runs inside mj_step; Python only writes a command.
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from converters.control_text import CONTROL_TEXT
from converters.mjcf.export_gravcomp import GRAVCOMP, restore_gravcomp
from converters.mjcf.export_servos import (
    EXPORTED,
    INTEGRAL_MARGIN,
    VELOCITY_MOTOR,
    export_servos,
)
from twin_cli.world import gravity_comp, sleeping, speed_holds

if TYPE_CHECKING:
    from collections.abc import Mapping

    from twin_cli.world.actuation import JointCommand

SPEED_MARGIN = 0.95  # ramp speed of a position move, as a fraction of the velocity limit
OVERSHOOT = 0.05  # most a position servo's speed may pass its ramp's while it catches up
HOLD = "hold"  # the kind of a velocity command of 0 held by friction (`twin_cli.world.speed_holds`)
HOLD_RULE = "speed 0: joint friction up to the effort limit"  # what `twin joints` shows for HOLD
MARK_SLOT, MARK = 9, 1.0  # dynprm entry that marks a servo reference (integrators ignore dynprm)
_INTEGRATOR = mujoco.mjtDyn.mjDYN_INTEGRATOR
_NONE = mujoco.mjtDyn.mjDYN_NONE
_AFFINE = mujoco.mjtBias.mjBIAS_AFFINE
_FIXED = mujoco.mjtGain.mjGAIN_FIXED


def give_reference(spec: mujoco.MjSpec) -> None:
    """Gives every plain joint motor of a robot spec its reference activation (see module doc),
    and a fixed-base robot its gravity compensation (`twin_cli.world.gravity_comp.prepare`).

    A plain motor (gain 1 on its input, no bias, no dynamics) pushes nothing until commanded, and
    with an integrator and ctrl 0 its activation stays 0, so an uncommanded robot is unchanged.
    Actuators with their own dynamics or bias (a rotor's lag, an MJCF position servo) are left
    as they are and take commands the older way (`twin_cli.world.actuation`).
    """
    for actuator in spec.actuators:
        plain = (
            actuator.trntype == mujoco.mjtTrn.mjTRN_JOINT
            and actuator.dyntype == _NONE
            and actuator.gaintype == _FIXED
            and actuator.biastype == mujoco.mjtBias.mjBIAS_NONE
            and not actuator.plugin.active  # a plugin computes its force (a gz-sim PID)
        )
        if plain:
            actuator.dyntype = _INTEGRATOR
            actuator.dynprm[MARK_SLOT] = MARK  # not an MJCF <intvelocity>: ours to rewrite
            speed_holds.remember_own(actuator, spec.joint(actuator.target))
    gravity_comp.prepare(spec)


def carry_exported_servos(spec: mujoco.MjSpec) -> None:
    """Gives a robot spec the servos its exported file carries (`converters.mjcf.export_servos`):
    the joints its tags command by position or velocity get MuJoCo's own servos, which the
    World then runs by ctrl (`twin_cli.world.native_servos`). A spec read from `twin convert`'s
    file has them already. The file's gravity compensation is handed to `gravity_comp`, which
    switches it with the commands, so an effort command lets an arm fall as in Gazebo."""
    text = spec.text(CONTROL_TEXT)
    if text is None:
        return
    records = json.loads(text.data)
    done = (EXPORTED, VELOCITY_MOTOR)
    if not any(isinstance(r, dict) and any(k in r for k in done) for r in records.values()):
        export_servos(spec)
        records = json.loads(text.data)
    handed = False
    for joint, record in records.items():
        motor = record.get(EXPORTED) if isinstance(record, dict) else None
        if motor and GRAVCOMP in motor:
            restore_gravcomp(spec, joint, motor.pop(GRAVCOMP))
            handed = True
    if handed:
        text.data = json.dumps(records)


def has_reference(model: mujoco.MjModel, a: int) -> bool:
    """Whether actuator `a` carries the reference activation `give_reference` adds."""
    return int(model.actuator_actnum[a]) == 1 and model.actuator_dynprm[a, MARK_SLOT] == MARK


def gains(
    mode: str,
    inertia: tuple[float, float],
    timestep: float,
    effort: float,
    speed: float,
    step: float,
) -> tuple[float, float]:
    """(kp, kv) of a servo at step h.

    Args:
        inertia: (I, I_c): the joint's own reflected inertia and the inertia it carries (≥ I)
            [kg m² or kg]. effort: its effort limit [N m or N]. speed: the ramp's speed [rad/s
            or m/s] (inf: a hold, or the start of a trajectory). step: |target − q| [rad or m].

    kv = I/h, the most damping a clamped step tolerates: an inner velocity loop that reaches
    the speed kp·(r − q)/kv asks of it in a few steps. A velocity servo's kp (its integral gain)
    is critically damped on INTEGRAL_MARGIN·I_c. A position servo's time constant τ = kv/kp is
    at least 4·I_c/kv (critically damped), and otherwise as short as the ramp allows: at most
    step/speed, so that the speed asked never passes the ramp's, and at most
    speed/(2·ε·a), so that the lag a joint of acceleration a = effort/I_c builds while it
    speeds up adds at most ε = OVERSHOOT of speed (a UR5e shoulder, 150 N m on 1.7 kg m², went
    to 2.2 times its limit with τ = 4 ms). A hold gets the stiffest servo: critically damped
    on I itself, so a trajectory is tracked tightly (its damping ratio on the carried inertia,
    at most HELD_RATIO·I, stays ≥ 0.58).
    """
    own, carried = inertia
    carried = max(carried, own)
    kv = own / timestep
    if mode == "velocity":
        return kv * kv / (4.0 * INTEGRAL_MARGIN * carried), kv
    if not math.isfinite(speed):
        return kv * kv / (4.0 * own), kv
    tau = 4.0 * carried / kv
    if speed > 0 and math.isfinite(effort) and effort > 0:
        tau = max(tau, min(step / speed, speed * carried / (2.0 * OVERSHOOT * effort)))
    return kv / tau, kv


def start(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    a: int,
    cmd: JointCommand,
    previous: str,
    lead: float = 0.0,
) -> None:
    """Sets the reference of a new command `cmd` (`kind` of the command before, "" for none).

    A servo continuing in its mode keeps its reference: a velocity change keeps the load it
    learnt, a new position target ramps on from where the last ramp was. A servo new to its
    mode starts its reference at the joint's position, as an `intvelocity` whose activation is
    set to it: the load a position servo held before is left for the integral to take up.

    A velocity change then steps the reference back by `lead` [rad or m]: the lag the damping
    builds while it brings the joint to its new speed, I_c·Δv/kv. An integral that stored that
    lag would pay it back as overshoot for seconds (a cart's wheels ran 2.6 % fast, and 1.6 %
    still after 3 s). A velocity servo that takes over from a HOLD starts at the joint (a
    friction stores nothing to carry over).
    """
    address = model.actuator_actadr[a]
    if previous == kind(cmd):
        data.act[address] -= lead
        return
    joint = int(model.actuator_trnid[a, 0])
    data.act[address] = float(data.qpos[model.jnt_qposadr[joint]]) - lead


def kind(cmd: JointCommand) -> str:
    """The command's mode, or HOLD for a velocity of 0 that the joint's friction holds."""
    return HOLD if speed_holds.is_hold(cmd.mode, cmd.target) else cmd.mode


def apply(model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand) -> None:
    """Writes a position or velocity command into actuator `a` (its force range is set)."""
    gear = abs(model.actuator_gear[a][0]) or 1.0
    joint = int(model.actuator_trnid[a, 0])
    address = int(model.actuator_actadr[a])
    model.actuator_dyntype[a] = _INTEGRATOR
    if kind(cmd) == HOLD:
        speed_holds.write(model, a, cmd.effort)
        model.actuator_actlimited[a] = 0
        data.ctrl[a] = 0.0
        return
    speed_holds.lift(model, a)
    model.actuator_biastype[a] = _AFFINE
    model.actuator_gainprm[a, 0] = cmd.kp / gear
    model.actuator_biasprm[a, 2] = -cmd.kv / gear**2
    low, high = _joint_range(model, joint)
    if cmd.mode == "velocity":
        speed, feedforward = cmd.target, cmd.target
    elif cmd.feedforward or not math.isfinite(cmd.velocity_limit):
        speed, feedforward = cmd.feedforward, cmd.feedforward
        if not cmd.feedforward:
            data.act[address] = cmd.target  # no velocity limit: the reference jumps
    else:
        here = float(data.act[address])
        speed = math.copysign(SPEED_MARGIN * cmd.velocity_limit, cmd.target - here)
        speed = 0.0 if here == cmd.target else speed
        low, high = min(here, cmd.target), max(here, cmd.target)
        feedforward = 0.0  # the ramp ends at the target; a lag 2v/ω is the price
    model.actuator_biasprm[a, 0] = cmd.kv * feedforward / gear
    model.actuator_biasprm[a, 1] = -cmd.kp / gear**2
    model.actuator_actlimited[a] = int(math.isfinite(low) or math.isfinite(high))
    model.actuator_actrange[a] = (low, high) if model.actuator_actlimited[a] else (0.0, 0.0)
    data.ctrl[a] = speed


def driven(cmd: JointCommand) -> bool:
    """Whether a servo drives its joint on until the next command: a non-zero velocity or a
    trajectory. A position ramp moves its joint from its first steps, which keeps the tree
    awake by MuJoCo's own rule, and lets it sleep once it holds its target."""
    if cmd.mode == "velocity":
        return cmd.target != 0.0
    return bool(cmd.feedforward)


def keep_awake(model: mujoco.MjModel, commands: Mapping[str, JointCommand]) -> None:
    """Keeps the trees of `driven` commands from sleeping until their next command, and lets
    every other commanded tree sleep (`sleeping.hold_awake`), decided when commands change. A
    plugin's PID (a gz-sim integral) keeps its tree awake: its integral changes its force while
    the joint rests, which a sleeping tree would not feel."""
    ids = {key: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, key) for key in commands}
    moving = [
        a
        for key, a in ids.items()
        if a >= 0 and (driven(commands[key]) or model.actuator_plugin[a] >= 0)
    ]
    awake = sleeping.actuator_trees(model, moving)
    resting = sleeping.actuator_trees(model, [a for a in ids.values() if a >= 0]) - awake
    sleeping.hold_awake(model, awake, True)
    sleeping.hold_awake(model, resting, False)


def release(model: mujoco.MjModel, a: int) -> None:
    """Stops the reference (effort mode): no dynamics, no range; the force ignores it."""
    speed_holds.lift(model, a)
    model.actuator_dyntype[a] = _NONE
    model.actuator_actlimited[a] = 0


def _joint_range(model: mujoco.MjModel, joint: int) -> tuple[float, float]:
    if model.jnt_limited[joint]:
        low, high = model.jnt_range[joint]
        return float(low), float(high)
    return -math.inf, math.inf


def follow(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    ids: np.ndarray,
    references: tuple[np.ndarray, np.ndarray, float],
    bias: np.ndarray,
) -> None:
    """Moves position servos along a trajectory at one controller update.

    Args:
        ids: actuator ids. references: (the reference now, the one due at the next update
            [rad or m], the time to it [s]). bias: the constant force term (kv·speed,
            per gear).
    Actuators with a reference activation (`has_reference`) start at the reference now and ramp
    to the next one in C, within their joint's range; the others aim at the next one (ctrl).
    """
    now, nxt, period = references
    held = np.array([has_reference(model, int(a)) for a in ids], dtype=bool)
    if held.any():
        ramped = ids[held]
        joints = model.actuator_trnid[ramped, 0]
        model.actuator_actlimited[ramped] = model.jnt_limited[joints]
        model.actuator_actrange[ramped] = np.where(
            model.jnt_limited[joints, None], model.jnt_range[joints], 0.0
        )
        data.act[model.actuator_actadr[ramped]] = now[held]
        data.ctrl[ramped] = (nxt[held] - now[held]) / period
    data.ctrl[ids[~held]] = nxt[~held]
    model.actuator_biasprm[ids, 0] = bias
