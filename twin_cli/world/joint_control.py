"""What a motor may be commanded to: its modes, bounds, PID gains and velocity limit, and the rule
that turns a command into servo gains.

The converter writes every motor's record into one `control` text (converters.mjcf.control_data);
a motor without one (hand-written MJCF) offers every mode with no velocity limit. The gain rules
(documented in docs/control.md):

- a plain motor, which carries a servo reference (`twin_cli.world.servos`): kv = I/h on the
  reflected inertia I = 1/(M⁻¹)ᵢᵢ, kp critically damped on the inertia the joint carries
  (`posture_loads`), or the tag's PID; see `servos.gains`.
- an actuator with its own bias or dynamics (no reference): position kp = I·min((MAX_OMEGA_DT/dt)²,
  v/(dt·|Δ|)) for a step of Δ, v = SPEED_MARGIN·v_max, kv = max(2·√(kp·I), kp·|Δ|/v) (an
  overdamped PD from rest never moves faster than v); velocity kv from `vel_kp`, else full
  effort at 5 % of the velocity limit, at most I/h with an effort limit (`_velocity_gain`).
- a fixed-base entity's weight: MuJoCo's gravity compensation (`twin_cli.world.gravity_comp`).
- effort: Gazebo's velocity rule (see twin_cli.world.actuation.apply_command).
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from converters.description import MODES
from converters.mjcf.export_servos import tag_pid, tag_servo_gains
from twin_cli.world import servos

# ω·dt of the position servo's spring (MuJoCo's implicit integrators leave springs explicit: < 2)
MAX_OMEGA_DT = 0.5
SPEED_MARGIN = 0.95  # position servo's design speed, as a fraction of the velocity limit
FULL_EFFORT_SPEED = 1.0  # [rad/s or m/s] velocity error at full effort without a velocity limit
# [rad or m] how far past a limit a position is still taken and clamped onto it: ros2_control's
# joint limiters accept a measured position this far out (joint_limits_helpers.hpp
# OUT_OF_BOUNDS_EXCEPTION_TOLERANCE: 0.5 degree, about 1 cm) and clamp commands into the range
LIMIT_TOLERANCE = 0.0087


@dataclass(frozen=True)
class JointLimits:
    """One motor's command modes and bounds.

    Attributes:
        modes: the modes it accepts. source: "ros2_control", "transmission", "default" (no
            tag) or "model" (no control record: a hand-written model).
        bounds: mode → (min, max) of the interface (None: unbounded side).
        pid: mode → (kp, ki, kd) from the tag. velocity: velocity limit [rad/s or m/s] (inf: none).
    """

    modes: tuple[str, ...] = MODES
    source: str = "model"
    bounds: dict = field(default_factory=dict)
    pid: dict = field(default_factory=dict)
    velocity: float = math.inf


def limits_of(model: mujoco.MjModel, entity: str, joint: str) -> JointLimits:
    """`joint`'s record in the `<entity>/control` text of `model`, or every mode unbounded."""
    record = record_of(model, entity, joint)
    if record is None:
        return JointLimits()
    velocity = record.get("velocity_limit")
    return JointLimits(
        tuple(record["modes"]),
        record["source"],
        {m: tuple(b) for m, b in record.get("bounds", {}).items()},
        {m: tuple(g) for m, g in record.get("pid", {}).items()},
        float(velocity) if velocity is not None and velocity > 0 else math.inf,
    )


def record_of(model: mujoco.MjModel, entity: str, joint: str) -> dict | None:
    """The joint's JSON record; MJCF converted before the records were merged (one
    `control:<joint>` text per motor) is read too."""
    records = _text_json(model, f"{entity}/control")
    if records is not None:
        return records.get(joint)
    return _text_json(model, f"{entity}/control:{joint}")


def _text_json(model: mujoco.MjModel, name: str) -> dict | None:
    """Text `name` as a JSON object (shared: read it, never change it); None if absent or not
    twin's (a hand-written model's)."""
    t = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, name)
    if t < 0:
        return None
    start = model.text_adr[t]
    return _json_object(bytes(model.text_data[start : start + model.text_size[t] - 1]))


@functools.lru_cache(maxsize=256)
def _json_object(text: bytes) -> dict | None:
    """`text` parsed once: a drive that commands its joints at every step reads the same
    records each time (parsing an entity's records took ~30 µs a joint per command)."""
    try:
        value = json.loads(text)
    except ValueError:
        return None
    return value if isinstance(value, dict) else None


def posture_loads(
    model: mujoco.MjModel,
    data: mujoco.MjData,
    targets: dict[int, float],
    dofs: np.ndarray | None = None,
    rolling: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reflected inertia [kg m² or kg] and static load [N m or N] of every dof, and the inertia
    each dof of `dofs` carries: with every other joint held by its servo, and for the dofs of
    `rolling` (velocity commands: wheels, tracks) through their contacts too.

    Computed at rest in the posture with the position `targets` (qpos address → value) written
    over the current one, on a scratch copy so the world's data (and warm start) stays untouched.
    The reflected inertia is 1/(M⁻¹)ᵢᵢ: what a torque at the joint accelerates, everything else
    free. The load is what holds that posture against gravity and springs: qfrc_bias −
    qfrc_passive. The carried inertia is Mᵢᵢ (every other joint held by its servo: an arm moving
    all its joints at once; at most HELD_RATIO times the reflected inertia), or, if larger, what
    a rolling joint moves through its contacts and equalities (`carried_inertia`: a wheel on the
    ground carries its robot). Only rolling joints count their contacts: a link that lies on the
    ground slides rather than rolls, and counted as gripping, it made an arm's position servo a
    hundred times too soft.
    """
    scratch = mujoco.MjData(model)
    scratch.qpos[:] = data.qpos
    for address, value in targets.items():
        scratch.qpos[address] = value
    mujoco.mj_forward(model, scratch)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, scratch, full)  # MuJoCo 4 signature: (m, d, dst)
    load = np.array(scratch.qfrc_bias) - np.array(scratch.qfrc_passive)
    inverse = np.linalg.inv(full)
    own = 1.0 / np.diag(inverse)
    carried = own.copy()
    if dofs is not None and len(dofs):  # every other joint held by its servo, up to a bound
        carried[dofs] = np.minimum(np.diag(full)[dofs], HELD_RATIO * own[dofs])
    if rolling is not None and len(rolling):
        through = carried_inertia(model, scratch, inverse, np.asarray(rolling))
        if len(rolling) > 1:  # wheels commanded together share their robot
            through = np.minimum(through, shared_inertia(model, scratch, inverse, rolling))
        carried[rolling] = np.maximum(carried[rolling], through)
    return own, load, carried


HELD_RATIO = 3.0
"""Most a joint's carried inertia counts from Mᵢᵢ, as a multiple of its own 1/(M⁻¹)ᵢᵢ. A fixed
arm's Mᵢᵢ is 1-4.4 times its own (UR5e); a free-standing robot's Mᵢᵢ also counts its base as held
(444 times for a UR5e's shoulder pan), which a servo whose damping is own/h cannot move quickly
anyway: tuned on all of it the servo only got slower. Past the bound the damping ratio may drop to
√(HELD_RATIO·own/Mᵢᵢ), 0.14 for that shoulder on the ground."""
CARRIED_CONSTRAINTS = (
    int(mujoco.mjtConstraint.mjCNSTR_EQUALITY),
    int(mujoco.mjtConstraint.mjCNSTR_CONTACT_FRICTIONLESS),
    int(mujoco.mjtConstraint.mjCNSTR_CONTACT_PYRAMIDAL),
    int(mujoco.mjtConstraint.mjCNSTR_CONTACT_ELLIPTIC),
)
MAX_CARRIED_RATIO = 1e4  # a joint its contacts lock completely counts as carrying this much


def shared_inertia(
    model: mujoco.MjModel, scratch: mujoco.MjData, inverse: np.ndarray, dofs: np.ndarray
) -> np.ndarray:
    """The inertia each of `dofs` carries when they all speed up together: the impulses
    (M_c⁻¹ restricted to dofs)⁺·1, with the contacts that move with any of them held rigid. Four
    wheels driven alike each carry a quarter of their cart, not all of it, as one wheel would;
    a dof whose share comes out non-positive keeps infinity (`carried_inertia` decides)."""
    active = _constraint_rows(model, scratch)
    rows = active[(np.abs(active[:, dofs]) > 0).any(axis=1)] if len(active) else active
    reduced = inverse[np.ix_(dofs, dofs)]
    if len(rows):
        mjt = inverse @ rows.T
        reduced = reduced - mjt[dofs] @ np.linalg.pinv(rows @ mjt, rcond=1e-10) @ mjt[dofs].T
    share = np.linalg.pinv(reduced, rcond=1e-8) @ np.ones(len(dofs))
    return np.where(share > 0, share, np.inf)


def _constraint_rows(model: mujoco.MjModel, scratch: mujoco.MjData) -> np.ndarray:
    """The active contact and equality rows of `scratch`'s constraint Jacobian (dense)."""
    if scratch.nefc == 0:
        return np.zeros((0, model.nv))
    jac = np.zeros((scratch.nefc, model.nv))
    if mujoco.mj_isSparse(model):
        mujoco.mju_sparse2dense(
            jac, scratch.efc_J, scratch.efc_J_rownnz, scratch.efc_J_rowadr, scratch.efc_J_colind
        )
    else:
        jac[:] = np.asarray(scratch.efc_J).reshape(scratch.nefc, model.nv)
    active = np.isin(scratch.efc_type, CARRIED_CONSTRAINTS) & (
        scratch.efc_state != int(mujoco.mjtConstraintState.mjCNSTRSTATE_SATISFIED)
    )
    return jac[active]


def carried_inertia(
    model: mujoco.MjModel, scratch: mujoco.MjData, inverse: np.ndarray, dofs: np.ndarray
) -> np.ndarray:
    """1/(M_c⁻¹)ᵢᵢ of each dof i of `dofs`, M_c⁻¹ = M⁻¹ − M⁻¹Jᵀ(J M⁻¹ Jᵀ)⁺J M⁻¹, where J are the
    active contact and equality rows that move with dof i itself, held rigid (`scratch` has
    been through mj_forward). A driven wheel that grips moves its robot with it, and a servo
    tuned on the wheel alone rings on that load; the robot's other contacts are left free
    (held rigid too, a wheel, a caster and a second wheel would lock the robot in place)."""
    own = 1.0 / np.diag(inverse)[dofs]
    active = _constraint_rows(model, scratch)
    reduced = np.diag(inverse)[dofs].copy()
    for i, dof in enumerate(dofs):
        rows = active[active[:, dof] != 0]
        if len(rows):
            mjt = inverse @ rows.T
            reduced[i] -= mjt[dof] @ np.linalg.pinv(rows @ mjt, rcond=1e-10) @ mjt[dof]
    floor = 1.0 / (MAX_CARRIED_RATIO * own)
    return 1.0 / np.maximum(reduced, floor)


def servo_rule(
    mode: str,
    limits: JointLimits,
    effort: float,
    inertia: float,
    timestep: float,
    step: float,
    *,
    reference: bool = False,
    carried: float = 0.0,
) -> tuple[float, float, str]:
    """(kp, kv, rule) for a command; `step` is |target − q| [rad or m] (position mode).

    Args:
        mode: the command's mode. limits: the motor's record. effort: effort limit [N m or N].
        inertia: reflected inertia [kg m² or kg]. timestep: [s]. step: |target − q| of a
        position command, |target| of a velocity command.
        reference: the motor tracks a reference in its activation (`twin_cli.world.servos`);
            otherwise the older rules below (actuators with their own bias or dynamics).
        carried: the inertia the joint carries through its contacts (`carried_inertia`).
    """
    pid = tag_pid(limits.pid, mode)
    if reference:
        speed = servos.SPEED_MARGIN * limits.velocity if step > 0 else math.inf  # inf: a hold
        motion = (speed, step)
        return _reference_rule(mode, pid, effort, (inertia, carried), timestep, motion)
    vmax = limits.velocity
    if mode == "position":
        kp, kv = _position_gains(inertia, timestep, step, SPEED_MARGIN * vmax)
        if pid:  # the tag's gains as the export writes them
            kp, kv = tag_servo_gains(pid, inertia, timestep, effort)
        return kp, kv, "tag PID (pos_kp, pos_kd)" if pid else "reflected inertia"
    if mode == "velocity":
        kv, rule = _velocity_gain(pid, effort, vmax, inertia, timestep)
        if math.isfinite(effort) and kv > inertia / timestep:
            return 0.0, inertia / timestep, f"{rule}, capped at I/h"
        return 0.0, kv, rule
    return 0.0, 0.0, "Gazebo velocity rule" if math.isfinite(vmax) else "effort"


def _reference_rule(
    mode: str,
    pid: tuple | None,
    effort: float,
    inertia: tuple[float, float],
    timestep: float,
    motion: tuple[float, float],
) -> tuple[float, float, str]:
    """(kp, kv, rule) of a servo on a reference: `servos.gains` unless the tag gives a PID.

    `motion` is (ramp speed, step) of a position command. A tag's damping above I/h is capped
    there when the joint has an effort limit (a clamped step is explicit, see `_velocity_gain`);
    otherwise its gains are used as written, with no damping added.
    """
    if mode == "effort":
        return 0.0, 0.0, "effort"
    own = inertia[0]
    kp, kv = servos.gains(mode, inertia, timestep, effort, *motion)
    rule = "carried inertia"
    if pid and mode == "position":
        kp, kv, rule = pid[0], max(pid[2], 0.0), "tag PID (pos_*)"  # Gazebo's p and d
    elif pid:  # the controller's p·(ω* − ω); its integral is not run, as in the export
        kp, kv, rule = 0.0, pid[0], "tag PID (vel_kp" + ("; vel_ki not run)" if pid[1] else ")")
    if pid and math.isfinite(effort) and kv > own / timestep:
        kv, rule = own / timestep, f"{rule}, damping capped at I/h"
    return kp, kv, rule


def _velocity_gain(
    pid: tuple | None, effort: float, vmax: float, inertia: float, timestep: float
) -> tuple[float, str]:
    """kv [N m s/rad or N s/m] of the velocity servo before the I/h cap, and its rule.

    The cap: MuJoCo integrates a motor's velocity feedback implicitly only while its force is
    inside `forcerange`; a clamped step is explicit, so with kv > I/h one step of full effort
    jumps past the target and the next brakes at full effort the other way. Measured on a cart
    whose wheels have effort 100 N m and v_max 1 rad/s (kv 2000 against I/h 0.6): the wheels
    swung ±117 rad/s every other step and the cart drifted and yawed. Without an effort limit
    the feedback is always implicit, so kv = I/h: the joint's own inertia reaches the target in
    about one step, and a load it drives through contact (a wheel's robot) still gets a usable
    torque per rad/s of error.
    """
    if pid:
        return pid[0], "tag PID (vel_kp)"
    if math.isfinite(effort) and math.isfinite(vmax):
        return effort / ((1.0 - SPEED_MARGIN) * vmax), "full effort at 5 % of v_max"
    if math.isfinite(effort):
        return effort / FULL_EFFORT_SPEED, "full effort at 1 rad/s error"
    return inertia / timestep, "I/h (no effort limit)"


def _position_gains(inertia: float, h: float, step: float, speed: float) -> tuple[float, float]:
    """kp, kv of the position servo on reflected inertia I for a step [rad or m] at time step h.

    kp = I·min(ω_max², speed/(h·step)), kv = max(2√(kp·I), kp·step/speed): overdamped enough
    that the joint approaches at most at `speed`, and kv ≤ I/h, so one step of full effort never
    carries the joint past the speed at which the servo starts braking (under saturation the
    damping is explicit).
    """
    omega2 = (MAX_OMEGA_DT / h) ** 2
    if math.isfinite(speed) and step > 0:
        omega2 = min(omega2, speed / (h * step))
    kp = inertia * omega2
    kv = 2.0 * math.sqrt(kp * inertia)
    if math.isfinite(speed):
        kv = max(kv, kp * step / speed)
    return kp, kv


def allowed_range(
    model: mujoco.MjModel, joint: int, mode: str, limits: JointLimits, effort: float
) -> tuple[float, float]:
    """The values a `mode` command may take: the joint's range, velocity or effort limit.

    A `<command_interface>`'s `min`/`max` (`limits.bounds`) is not among them: gazebo_ros2_control
    and gz_ros2_control pass each command to the joint as the controller wrote it, so a wheel
    interface declared ±1 still turns at the 6 rad/s its drive asks for.
    """
    if mode == "position" and model.jnt_limited[joint]:
        low, high = (float(v) for v in model.jnt_range[joint])
        return low, high
    if mode == "velocity":
        return -limits.velocity, limits.velocity
    if mode == "effort":
        return -effort, effort
    return -math.inf, math.inf


def onto_range(value: float, low: float, high: float) -> float | None:
    """A position [rad or m] clamped into [low, high] when it is at most LIMIT_TOLERANCE outside
    (a joint resting on its limit, a target read from one); None when it is further out."""
    if low - LIMIT_TOLERANCE <= value <= high + LIMIT_TOLERANCE:
        return min(max(value, low), high)
    return None
