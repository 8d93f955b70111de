"""Gains of an exported position servo: stiff, damped so that a move bounded by the effort stops.

A position servo's law is f = clamp(kp·(target − q) − kv·q̇, ±effort). Two rules set it:
  - stiffness: kp = I·ω² on the joint's reflected inertia I at the home posture, with the natural
    frequency ω as high as the step h integrates well (ω·h = OMEGA_STEP). Menagerie's hand-tuned
    arms are as stiff (its Panda: 4500 N m/rad on joint 1, here 5020).
  - damping: kv = kp·τ, τ the longest of three times. 2ζ/ω is critical damping at home
    (ζ = DAMPING_RATIO, MuJoCo's `dampratio`). √(2·B·I_max/effort) keeps a move that saturates
    the effort from overshooting where the joint is heaviest (I_max, the largest reflected
    inertia over the joint's range): the force leaves its bound on the line q̇ = (target − q)/τ
    and brakes along it, which the effort can do only while q̇/τ ≤ effort/I_max; it is the time
    the effort takes to move I_max across B = BRAKE_RAD. B/v_max makes the servo ask for at most
    the velocity limit within B of its target, so that light joints do not whirl (a UR5e wrist
    of 1.3e-4 kg m² and ±28 N m reached 874 rad/s in the random-ctrl gate without it, 223 with).
Critical damping alone (τ = 2/ω = 10 ms at the 1 ms step) overshot a 1 rad step of a Panda-like
arm's first joint by 0.80 rad and settled in 2.6 s where the arm is extended (I 2.4 kg m²
against 0.13 at home); these gains settle it in 0.61-0.69 s without overshoot, at most 3.6 times
its velocity limit, under `implicit` and `implicitfast` alike.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import mujoco

# A servo's natural frequency ω times the step h. `implicit` and `implicitfast` integrate the
# damping implicitly and the stiffness explicitly. Measured, 10 s of random ctrl (the corpus
# gate) on the Panda-like arm, ur5e, open_manipulator_x and robotiq_2f_85 stays finite without
# warnings for ω·h from 0.2 to 4; on the Panda-like arm ω·h = 0.1 and 0.2 settle every step within
# 10 % of each other. 0.2 keeps a twentyfold margin.
OMEGA_STEP = 0.2
DAMPING_RATIO = 1.0  # critical damping on the joint's reflected inertia at home
# [rad] B, the move the effort must be able to stop within τ (module doc). Measured over 4
# postures, 7 joints and steps of 0.1-1 rad of a Panda-like arm (without the velocity term): 0.1
# rad overshot by up to 510 mrad, 0.15 by 261 mrad, 0.25 by none, and every step settled within
# 1.3·Δ/v_max + 0.3 s (at most 0.95 of it).
BRAKE_RAD = 0.25
# On a joint of a short range (a gripper's finger) B is at most this share of the range.
RANGE_SHARE = 0.25
POSTURES = 64  # random postures sampled for the largest reflected inertia
SEED = 0  # of those postures: the same file on every run


def position_gains(
    inertia: float, largest: float, effort: float, speed: float | None, span: float, timestep: float
) -> tuple[float, float]:
    """(kp [N m/rad], kv [N m s/rad]) of a position servo (module doc; [N/m], [N s/m] on a slide).

    Args:
        inertia: the joint's reflected inertia at home [kg m² or kg].
        largest: its largest reflected inertia over the joint's range (≥ `inertia`).
        effort: its effort limit [N m or N]; inf: none.
        speed: its velocity limit [rad/s or m/s]; None or inf: none.
        span: its range's width [rad or m]; inf: none.
        timestep: the model's step [s].
    """
    omega = OMEGA_STEP / timestep
    kp = inertia * omega * omega
    brake = min(BRAKE_RAD, RANGE_SHARE * span)
    tau = 2.0 * DAMPING_RATIO / omega
    if np.isfinite(effort) and effort > 0.0:
        tau = max(tau, float(np.sqrt(2.0 * brake * max(largest, inertia) / effort)))
    if speed is not None and np.isfinite(speed) and speed > 0.0:
        tau = max(tau, brake / speed)
    return kp, kp * tau


def largest_inertia(model: mujoco.MjModel) -> np.ndarray:
    """Each DoF's largest reflected inertia (`reflected_inertia`) over POSTURES random postures
    of the hinge and slide joints within their ranges (a hinge without one: a turn), and qpos0."""
    import mujoco

    data = mujoco.MjData(model)
    rng = np.random.default_rng(SEED)
    largest = _diagonal(model, data)
    moving = [
        j
        for j in range(model.njnt)
        if int(model.jnt_type[j])
        in (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
    ]
    for _ in range(POSTURES):
        data.qpos[:] = model.qpos0
        for j in moving:
            low, high = _sample_range(model, j)
            data.qpos[model.jnt_qposadr[j]] = rng.uniform(low, high)
        largest = np.maximum(largest, _diagonal(model, data))
    return largest


def _sample_range(model: mujoco.MjModel, joint: int) -> tuple[float, float]:
    """The joint's range; without one, a turn for a hinge and its qpos0 for a slide."""
    import mujoco

    if model.jnt_limited[joint]:
        return float(model.jnt_range[joint, 0]), float(model.jnt_range[joint, 1])
    if int(model.jnt_type[joint]) == int(mujoco.mjtJoint.mjJNT_HINGE):
        return -np.pi, np.pi
    q0 = float(model.qpos0[model.jnt_qposadr[joint]])
    return q0, q0


def _diagonal(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """`reflected_inertia` of every dof at `data.qpos` [kg m² or kg]."""
    import mujoco

    mujoco.mj_kinematics(model, data)
    mujoco.mj_comPos(model, data)
    mujoco.mj_makeM(model, data)
    full = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, full)  # MuJoCo 4 signature: (m, d, dst)
    return reflected_inertia(model, full)


def reflected_inertia(model: mujoco.MjModel, full: np.ndarray) -> np.ndarray:
    """Each dof's inertia as its servo's step sees it [kg m² or kg]: the robot's other joints
    held (their servos are stiff), its floating base free. On a fixed base that is the
    mass-matrix diagonal Mᵢᵢ; a floating base turns against the joint, so a hinge's inertia is
    1/((M_S)⁻¹)ᵢᵢ over S = the hinge and the base's dofs. A UR5e standing free on its base has
    3.4 kg m² on its shoulder pan as Mᵢᵢ and 0.007 with its 4 kg base turning: a servo tuned on
    Mᵢᵢ chattered at ±150 N m, spinning the base, where the base's floor friction holds ~10 N m.
    """
    import mujoco

    diagonal = np.diag(full).copy()
    free = [
        int(model.jnt_dofadr[j]) + k
        for j in range(model.njnt)
        if int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_FREE)
        for k in range(6)
    ]
    if not free:
        return diagonal
    for dof in range(model.nv):
        if dof in free:
            continue
        rows = [dof, *free]
        sub = full[np.ix_(rows, rows)]
        diagonal[dof] = 1.0 / np.linalg.inv(sub)[0, 0]
    return diagonal
