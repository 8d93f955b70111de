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

    force = kp·(r − q) + kv·(ṙ_ff − q̇) + hold,   within ±effort

- velocity v*: ctrl = v*, ṙ_ff = v*, r starts at q. kp·(r − q) = kp·∫(v* − q̇)dt is the integral
  term of a PI velocity servo: under a constant load the joint runs at v* exactly.
  `limit_windup` (an observer at WINDUP_RATE) keeps the integral where the effort limit leaves
  it room, so a spin-up or a stall does not store a catch-up burst for later. A limited joint's
  r stays in its range (`actrange`), so a command into a limit does not wind up either.
- position q*: r ramps from q to q* at 0.95·v_max and stops there (`actrange` clamps it); the PD
  is overdamped and tracks the ramp 2·v/ω behind, then settles
  without overshoot (the error after the ramp is (2v/ω + v·t)·e^(−ωt), never negative). A 1 rad
  move at 1 rad/s settles within 1 % in about 1.1 s. Without a velocity limit r jumps to q*.
- trajectory: the follower writes r and its speed at each update; r ramps between updates.
- a fixed-base robot's position servo adds the static load (gravity, springs) of the posture,
  interpolated along the move by the joint's own position: the start posture's load at the start,
  the target's at the target. Holding the target's load from the start pushed a UR5e's shoulder
  to 2.2 times its velocity limit.

kv = I/h on the joint's own reflected inertia I, the most damping a clamped step tolerates, and
kp critically damped on the inertia I_c the joint carries when the command arrives
(`twin_cli.world.joint_control.posture_loads`: its other joints held, and a wheel's robot through
its contacts), with INTEGRAL_MARGIN for velocity. A wheel carries its robot: tuned on the wheel
alone, a cart's wheels rang to 1.34 rad/s on a 1 rad/s command.
Everything runs inside mj_step; Python only writes a command, and the windup observer
reads a few numbers at WINDUP_RATE.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from converters.control_text import CONTROL_TEXT
from converters.mjcf.export_servos import EXPORTED
from twin_cli.world import sleeping

if TYPE_CHECKING:
    from collections.abc import Iterable

    from twin_cli.world.actuation import JointCommand

INTEGRAL_MARGIN = 8.0
"""A velocity servo's kp is its integral gain. A velocity step makes it store the lag of the
damping term and give it back as overshoot, about 1/(4·INTEGRAL_MARGIN) of the step (3 %) when
the carried inertia is right, less when it is overestimated; the integral then settles a load in
about 4·INTEGRAL_MARGIN·I_c/kv."""
SPEED_MARGIN = 0.95  # ramp speed of a position move, as a fraction of the velocity limit
OVERSHOOT = 0.05  # most a position servo's speed may pass its ramp's while it catches up
LEAK_S = 0.5
"""[s] how fast a stopped servo forgets an integral it is paying back. An integral also stores
the lag of a speed change the damping could not follow (a light wheel dragged on by its
robot while it brakes) and pays it back later: a turtlebot stopped after a drive turned its
wheels back for a minute (1.1-1.7 mrad of yaw in 60 s). So while a servo commanded to 0 moves
towards its reference (mean |q̇| > LEAK_SPEED, the sign of r − q) within LEAK_WINDOW_S of its
stop, the integral decays; a load that pushes the joint away from its reference, or holds it
still, keeps it."""
LEAK_SPEED = 1e-5  # [rad/s or m/s]
LEAK_WINDOW_S = 3.0
"""[s] how long after a servo is given speed 0 it may still forget its integral. A lag is paid
back in the first seconds after a stop; later the integral holds a load (a wheel parked on a
slope), and letting it leak whenever chatter swings the joint back made a held turtlebot3 creep
0.08 mm/s down a 5° slope."""
HELD_FROM_LOAD = "held from load"
"""The rule of a drive plugin's hold from spawn (`twin_cli.world.plugin_holds`). Its gains were
derived before the robot's contacts were known, so the next velocity command derives its own;
it stored no lag, so its integral never leaks (a leak let a held base creep down a slope)."""
WINDUP_RATE = 100.0  # [Hz] of sim time at which a velocity servo's reference is kept near q
MARK_SLOT, MARK = 9, 1.0  # dynprm entry that marks a servo reference (integrators ignore dynprm)
_INTEGRATOR = mujoco.mjtDyn.mjDYN_INTEGRATOR
_NONE = mujoco.mjtDyn.mjDYN_NONE
_AFFINE = mujoco.mjtBias.mjBIAS_AFFINE
_FIXED = mujoco.mjtGain.mjGAIN_FIXED


def give_reference(spec: mujoco.MjSpec) -> None:
    """Gives every plain joint motor of a robot spec its reference activation (see module doc).

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
        )
        if plain:
            actuator.dyntype = _INTEGRATOR
            actuator.dynprm[MARK_SLOT] = MARK  # not an MJCF <intvelocity>: ours to rewrite


def restore_exported_motors(spec: mujoco.MjSpec) -> None:
    """Turns the servos an exported file carries for MuJoCo users back into the torque motors
    they replaced (`converters.mjcf.export_servos`), so a World commands a robot spawned from
    `twin convert`'s file exactly as it commands the robot's source."""
    text = spec.text(CONTROL_TEXT)
    if text is None:
        return
    records = json.loads(text.data)
    restored = False
    for actuator in spec.actuators:
        motor = records.get(actuator.target, {}).pop(EXPORTED, None)
        if motor is None:
            continue
        actuator.set_to_motor()
        actuator.ctrlrange = np.array(motor["ctrlrange"], dtype=float)
        actuator.ctrllimited = mujoco.mjtLimited(motor["ctrllimited"])
        actuator.forcerange = np.array(motor["forcerange"], dtype=float)
        actuator.forcelimited = mujoco.mjtLimited(motor["forcelimited"])
        restored = True
    if restored:
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
    """Sets the reference of a new command `cmd` (mode `previous` before, "" for none).

    A servo continuing in its mode keeps its reference: a velocity change keeps the load it
    learnt, a new position target ramps on from where the last ramp was. A new position servo
    starts its ramp at the joint's position. A velocity servo that takes over from a position
    servo starts with its integral carrying the force that servo applied (bumpless transfer):
    it holds an arm's weight from its first step instead of letting the arm sag until its
    integral has learnt the load again. (An effort command's force is a command, not a load.)

    A velocity change then steps the reference back by `lead` [rad or m]: the lag the damping
    builds while it brings the joint to its new speed, I_c·Δv/kv. An integral that stored that
    lag would pay it back as overshoot for seconds (a cart's wheels ran 2.6 % fast, and 1.6 %
    still after 3 s). What a stopped servo still pays back decays (`limit_windup`).
    """
    address = model.actuator_actadr[a]
    if previous == cmd.mode:
        data.act[address] -= lead
        return
    joint = int(model.actuator_trnid[a, 0])
    reference = float(data.qpos[model.jnt_qposadr[joint]])
    if cmd.mode == "velocity" and previous == "position" and cmd.kp > 0:
        gear = abs(model.actuator_gear[a][0]) or 1.0
        carried = float(data.actuator_force[a]) * gear
        if math.isfinite(cmd.effort):
            carried = min(max(carried, -cmd.effort), cmd.effort)
        reference += carried / cmd.kp
    data.act[address] = reference - lead


def apply(model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand) -> None:
    """Writes a position or velocity command into actuator `a` (its force range is set)."""
    gear = abs(model.actuator_gear[a][0]) or 1.0
    joint = int(model.actuator_trnid[a, 0])
    address = int(model.actuator_actadr[a])
    model.actuator_dyntype[a] = _INTEGRATOR
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
    hold = cmd.hold - cmd.hold_slope * cmd.target  # + hold_slope·q through biasprm[1]
    model.actuator_biasprm[a, 0] = (cmd.kv * feedforward + hold) / gear
    model.actuator_biasprm[a, 1] = (cmd.hold_slope - cmd.kp) / gear**2
    model.actuator_actlimited[a] = int(math.isfinite(low) or math.isfinite(high))
    model.actuator_actrange[a] = (low, high) if model.actuator_actlimited[a] else (0.0, 0.0)
    data.ctrl[a] = speed
    sleeping.hold_awake(model, sleeping.actuator_trees(model, (a,)), moving(model, data, a, cmd))


def moving(model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand) -> bool:
    """Whether a servo still drives its joint somewhere: a non-zero velocity, a trajectory,
    or a position ramp that has not reached its target."""
    if cmd.mode == "velocity":
        return cmd.target != 0.0
    if cmd.feedforward or data.ctrl[a] != 0.0:
        return float(data.act[model.actuator_actadr[a]]) != cmd.target or bool(cmd.feedforward)
    return False


def release(model: mujoco.MjModel, a: int) -> None:
    """Stops the reference (effort mode): no dynamics, no range; the force ignores it."""
    model.actuator_dyntype[a] = _NONE
    model.actuator_actlimited[a] = 0


def _joint_range(model: mujoco.MjModel, joint: int) -> tuple[float, float]:
    if model.jnt_limited[joint]:
        low, high = model.jnt_range[joint]
        return float(low), float(high)
    return -math.inf, math.inf


@dataclass
class WindupMemory:
    """What the servo observer keeps between calls, per actuator name (ids shift when an entity
    is deleted): its joint's position with the sim time, its speed target with the sim time it
    was first seen (time that went back, a reset, starts both afresh), and its id in the model."""

    position: dict[str, tuple[float, float]] = field(default_factory=dict)
    target: dict[str, tuple[float, float]] = field(default_factory=dict)
    model: mujoco.MjModel | None = None
    servo_ids: dict[str, int] = field(default_factory=dict)

    def servo(self, model: mujoco.MjModel, key: str) -> int:
        """The id of actuator `key` if it carries a reference activation, else -1; looked up
        once per compiled model (the observer runs at WINDUP_RATE)."""
        if model is not self.model:
            self.model, self.servo_ids = model, {}
        a = self.servo_ids.get(key)
        if a is None:
            a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, key)
            a = self.servo_ids[key] = a if a >= 0 and has_reference(model, a) else -1
        return a

    def mean_speed(self, key: str, q: float, now: float) -> float:
        """The joint's mean speed since the previous call [rad/s or m/s] (0 at the first)."""
        before = self.position.get(key)
        self.position[key] = (now, q)
        if before is None or now <= before[0]:
            return 0.0
        return (q - before[1]) / (now - before[0])

    def held_for(self, key: str, target: float, now: float) -> float:
        """[s] how long the servo has had this speed target."""
        seen = self.target.get(key)
        if seen is None or seen[0] != target or now < seen[1]:
            seen = self.target[key] = (target, now)
        return now - seen[1]


def limit_windup(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    servos: Iterable[tuple[int, JointCommand]],
    memory: WindupMemory,
) -> None:
    """Clamps each velocity servo's integral e = r − q so that kv·(v* − q̇) + kp·e stays within
    ±effort, and lets it grow only towards the side with room left: while the damping term alone
    saturates the joint (spinning up, stalled), the integral does not grow, so the joint reaches
    its speed, or leaves a stall, without a catch-up burst; a stopped servo forgets a lag it
    pays back (LEAK_S).

    Args:
        servos: (actuator id, its velocity command) with kp > 0.
        memory: kept by the caller between calls. Whether a joint moves towards its
            reference is read from its mean speed since the previous call, not from its speed
            now, which contact chatter flips from step to step; and only within LEAK_WINDOW_S
            of its stop.
    """
    keep = math.exp(-1.0 / (WINDUP_RATE * LEAK_S))
    for a, cmd in servos:
        joint = int(model.actuator_trnid[a, 0])
        q = float(data.qpos[model.jnt_qposadr[joint]])
        speed = float(data.qvel[model.jnt_dofadr[joint]])
        damping = cmd.kv * (cmd.target - speed)
        effort = cmd.effort if math.isfinite(cmd.effort) else math.inf
        low = min(0.0, (-effort - damping) / cmd.kp)
        high = max(0.0, (effort - damping) / cmd.kp)
        address = int(model.actuator_actadr[a])
        error = min(max(float(data.act[address]) - q, low), high)
        now = float(data.time)
        mean_speed = memory.mean_speed(cmd.actuator, q, now)
        stopping = memory.held_for(cmd.actuator, cmd.target, now) < LEAK_WINDOW_S
        back = abs(mean_speed) > LEAK_SPEED and error * mean_speed > 0.0
        if cmd.target == 0.0 and stopping and back and cmd.rule != HELD_FROM_LOAD:
            error *= keep  # paying back a stored lag (LEAK_S)
        data.act[address] = q + error


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
            [rad or m], the time to it [s]). bias: the constant force term (kv·speed + hold,
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
