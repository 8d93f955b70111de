"""Joint commands (position, velocity, effort), timed pushes and Gazebo dampingFactor.

Joint commands reuse the entity's motor actuator (one per actuated joint, `ctrlrange` = ±effort,
converter contract). Effort mode keeps it a motor. Position and velocity modes turn it into a PD
servo *inside MuJoCo* by rewriting its gain and bias (force = kp·(target − q) − kv·q̇, clipped to
±effort through `forcerange`), so the PD runs in C at every step with no Python in the hot path,
and `implicitfast` integrates the kv term implicitly. Commands are rewritten into each new model
after a recompile, since compiling restores the spec's motor.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

MODES = ("position", "velocity", "effort")
FULL_EFFORT_ERROR = 0.1  # [rad or m] position error at which the PD reaches full effort
FULL_EFFORT_SPEED = 1.0  # [rad/s or m/s] velocity error at which the servo reaches full effort
MAX_OMEGA_DT = 0.5  # ω·dt cap on the position servo's natural frequency (explicit stiffness)
UNLIMITED_OMEGA = 30.0  # [rad/s] servo natural frequency for a joint without effort limit
GAZEBO_STEP = 0.001  # [s] dampingFactor is the velocity fraction lost per Gazebo step
_AFFINE = mujoco.mjtBias.mjBIAS_AFFINE
_NONE = mujoco.mjtBias.mjBIAS_NONE
_FIXED = mujoco.mjtGain.mjGAIN_FIXED


@dataclass(frozen=True)
class JointCommand:
    """A joint target held until replaced or reset.

    Attributes:
        actuator: full actuator name ("<entity>/<joint>'s motor").
        mode: "position" | "velocity" | "effort".
        target: clipped target [rad, m, rad/s, m/s, N m or N].
        kp: stiffness [N m/rad or N/m] (position mode); kv: damping [N m s/rad or N s/m].
        effort: the joint's effort limit [N m or N] (inf when unlimited).
    """

    actuator: str
    mode: str
    target: float
    kp: float
    kv: float
    effort: float


def effort_limit(model: mujoco.MjModel, actuator: int) -> float:
    """The most force [N m or N] the motor can apply at its joint (inf when unlimited)."""
    gear = abs(model.actuator_gear[actuator][0]) or 1.0
    limits = []
    if model.actuator_ctrllimited[actuator]:
        limits.append(np.max(np.abs(model.actuator_ctrlrange[actuator])) * gear)
    if model.actuator_forcelimited[actuator]:
        limits.append(np.max(np.abs(model.actuator_forcerange[actuator])) * gear)
    return float(min(limits)) if limits else math.inf


def servo_gains(mode: str, effort: float, inertia: float, timestep: float) -> tuple[float, float]:
    """PD gains (kp, kv) for a joint of effective inertia `inertia` [kg m² or kg].

    kp reaches full effort at FULL_EFFORT_ERROR, capped so the servo's natural frequency
    ω = √(kp/I) keeps ω·dt ≤ MAX_OMEGA_DT; kv damps it critically (2√(kp·I)). Velocity mode
    reaches full effort at FULL_EFFORT_SPEED.
    """
    if mode == "effort":
        return 0.0, 0.0
    if mode == "velocity":
        kv = effort / FULL_EFFORT_SPEED if math.isfinite(effort) else inertia * UNLIMITED_OMEGA
        return 0.0, kv
    kp = effort / FULL_EFFORT_ERROR if math.isfinite(effort) else inertia * UNLIMITED_OMEGA**2
    kp = min(kp, inertia * (MAX_OMEGA_DT / timestep) ** 2)
    return kp, 2.0 * math.sqrt(kp * inertia)


def clip_target(model: mujoco.MjModel, joint: int, mode: str, value: float, effort: float) -> float:
    """The target clipped to the joint's range (position) or effort limit (effort)."""
    if mode == "position" and model.jnt_limited[joint]:
        low, high = model.jnt_range[joint]
        return float(min(max(value, low), high))
    if mode == "effort" and math.isfinite(effort):
        return float(min(max(value, -effort), effort))
    return float(value)


def apply_command(model: mujoco.MjModel, data: mujoco.MjData, a: int, cmd: JointCommand) -> None:
    """Writes `cmd` into actuator `a` of `model` (gains, ranges) and `data.ctrl`."""
    gear = abs(model.actuator_gear[a][0]) or 1.0
    limit = cmd.effort / gear
    model.actuator_gaintype[a] = _FIXED
    model.actuator_gainprm[a, :3] = 0.0
    model.actuator_biasprm[a, :3] = 0.0
    model.actuator_ctrllimited[a] = 0
    model.actuator_forcelimited[a] = int(math.isfinite(limit))
    model.actuator_forcerange[a] = (-limit, limit) if math.isfinite(limit) else (0.0, 0.0)
    if cmd.mode == "effort":
        model.actuator_gainprm[a, 0] = 1.0
        model.actuator_biastype[a] = _NONE
        data.ctrl[a] = cmd.target / gear
        return
    model.actuator_biastype[a] = _AFFINE
    if cmd.mode == "position":
        model.actuator_gainprm[a, 0] = cmd.kp / gear
        model.actuator_biasprm[a, 1] = -cmd.kp / gear
    else:
        model.actuator_gainprm[a, 0] = cmd.kv / gear
    model.actuator_biasprm[a, 2] = -cmd.kv / gear
    data.ctrl[a] = cmd.target


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


@dataclass(frozen=True)
class Damping:
    """Per-step velocity decay of the dofs of bodies with Gazebo `dampingFactor`.

    Attributes:
        dofs: dof addresses; keep: factor each velocity is multiplied by per world step.
    """

    dofs: np.ndarray
    keep: np.ndarray


def damping_of(model: mujoco.MjModel, names: list[str]) -> Damping | None:
    """Reads `<prefix>damping_factor:<body>` numerics into a per-step decay, or None if none.

    `names` are the model's numeric names (index i ↔ numeric i).

    A fraction f lost per GAZEBO_STEP becomes (1 − f)^(dt / GAZEBO_STEP) per world step, applied
    to the velocity of the body's own joints (exact for a free body; for a body on a joint, the
    decay acts on the joint speed).
    """
    dofs, keep = [], []
    for i, name in enumerate(names):
        prefix, sep, body = name.partition("damping_factor:")
        if not sep:
            continue
        b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, prefix + body)
        fraction = float(model.numeric_data[model.numeric_adr[i]])
        if b < 0 or fraction <= 0:
            continue
        span = range(model.body_dofadr[b], model.body_dofadr[b] + model.body_dofnum[b])
        factor = (1.0 - min(fraction, 1.0)) ** (model.opt.timestep / GAZEBO_STEP)
        dofs.extend(span)
        keep.extend([factor] * len(span))
    return Damping(np.array(dofs, np.int64), np.array(keep)) if dofs else None
