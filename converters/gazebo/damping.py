"""Gazebo `dampingFactor` as MuJoCo joint damping on the tagged body's own joints.

sdformat's URDF parser writes `<dampingFactor>f</dampingFactor>` as the link's
`<velocity_decay><linear>f</linear><angular>f</angular>`; Gazebo Classic hands both to ODE
(`dBodySetLinearDamping`, `dBodySetAngularDamping`), whose `dxStepBody` multiplies the body's
linear and angular velocity by (1 − f) after every step (ODE `util.cpp`), while the speed is
above 0.01 m/s (0.01 rad/s). At Gazebo's 1 ms step that is the rate λ = −ln(1 − f)/0.001 s.

MuJoCo integrates joint damping b implicitly (Euler, implicit, implicitfast): one step keeps
M/(M + h·b) of a dof's velocity. With b = K·M and K = f/((1 − f)·h_gz) that keeps exactly
1 − f per 1 ms step, so the decay is Gazebo's at twin's default step and lives in the MJCF.
M is what ODE damps: the body's mass for a slide and for a free body's translation, the body's
own inertia about the axis for a hinge. A joint's damping is one number for all its dofs, so a
free body's rotation decays m/I times faster than Gazebo's (reported with the figures).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.gazebo.contact import GAZEBO_STEP

if TYPE_CHECKING:
    import mujoco

ODE_DAMPING_THRESHOLD = 0.01  # [m/s], [rad/s] ODE damps no slower body (dWorldCreate defaults)


@dataclass(frozen=True)
class JointDamping:
    """The damping one joint gets for its body's `dampingFactor`.

    Attributes:
        joint: joint name; kind: "free", "ball", "hinge" or "slide".
        damping: added joint damping [N s/m or N m s/rad].
        inertia: what it scales: mass [kg] or inertia about the axis [kg m²].
        rotation_ratios: free and ball joints: per principal axis, MuJoCo's rotational decay
            rate over Gazebo's (1 = exact); empty for hinge and slide.
    """

    joint: str
    kind: str
    damping: float
    inertia: float
    rotation_ratios: tuple[float, ...] = ()


def decay_rate(fraction: float) -> float:
    """K [1/s] with which b = K·M keeps 1 − `fraction` of the velocity per 1 ms implicit step."""
    kept = 1.0 - min(fraction, 0.999999)
    return fraction / (kept * GAZEBO_STEP)


def body_joint_damping(model: mujoco.MjModel, body: str, fraction: float) -> list[JointDamping]:
    """The joint damping of each of `body`'s own joints for a `dampingFactor` of `fraction`.

    Args:
        model: a model compiled from the robot's spec (names as in the spec).
        body: the body carrying the tagged link.
        fraction: velocity fraction lost per 1 ms Gazebo step, in [0, 1].

    Returns:
        One entry per joint of the body (empty for a body welded to its parent).
    """
    import mujoco

    b = model.body(body).id
    rate = decay_rate(fraction)
    mass = float(model.body_mass[b])
    inertia = _body_frame_inertia(model, b)
    out = []
    for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
        kind = mujoco.mjtJoint(model.jnt_type[j])
        name = model.joint(j).name
        if kind == mujoco.mjtJoint.mjJNT_SLIDE:
            out.append(JointDamping(name, "slide", rate * mass, mass))
        elif kind == mujoco.mjtJoint.mjJNT_HINGE:
            about = _about_axis(model, b, j, inertia)
            out.append(JointDamping(name, "hinge", rate * about, about))
        else:
            principal = np.maximum(model.body_inertia[b], 1e-12)
            free = kind == mujoco.mjtJoint.mjJNT_FREE
            scale = mass if free else float(np.max(principal))
            ratios = tuple(float(scale / i) for i in principal)
            label = "free" if free else "ball"
            out.append(JointDamping(name, label, rate * scale, scale, ratios))
    return out


def _body_frame_inertia(model: mujoco.MjModel, b: int) -> np.ndarray:
    """The body's inertia tensor about its centre of mass, in the body frame [kg m²]."""
    import mujoco

    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body_iquat[b])
    r = rot.reshape(3, 3)
    return r @ np.diag(model.body_inertia[b]) @ r.T


def _about_axis(model: mujoco.MjModel, b: int, j: int, inertia: np.ndarray) -> float:
    """The body's own inertia about hinge j's axis [kg m²] (parallel-axis term included)."""
    axis = model.jnt_axis[j] / np.linalg.norm(model.jnt_axis[j])
    arm = np.cross(model.body_ipos[b] - model.jnt_pos[j], axis)
    return float(axis @ inertia @ axis + model.body_mass[b] * arm @ arm)


def describe(fraction: float, joints: list[JointDamping]) -> tuple[str, bool]:
    """The report text for one body and whether it is approximated (free/ball rotation, or a
    body with no joint of its own)."""
    rate = -np.log(1.0 - min(fraction, 0.999999)) / GAZEBO_STEP
    head = (
        f"dampingFactor={fraction:g}: Gazebo keeps {1 - fraction:.6g} of the link's velocity per "
        f"1 ms step (rate {rate:.4g}/s); joint damping b = {decay_rate(fraction):.6g}/s × M "
        "keeps the same per 1 ms implicit step"
    )
    if not joints:
        return head + "; the body has no joint of its own: not applied", True
    parts = [f"'{j.joint}' ({j.kind}) b={j.damping:.6g} on M={j.inertia:.6g}" for j in joints]
    text = head + ": " + ", ".join(parts)
    rotating = [j for j in joints if j.rotation_ratios]
    for j in rotating:
        ratios = "/".join(f"{r:.4g}" for r in j.rotation_ratios)
        text += (
            f"; '{j.joint}' rotation decays {ratios} times Gazebo's rate about the principal axes "
            "(one damping for all its dofs)"
        )
    text += (
        f"; below {ODE_DAMPING_THRESHOLD} m/s ODE stops damping, MuJoCo does not; at another step "
        "h the kept fraction is 1/(1 + h·b/M) per step"
    )
    return text, bool(rotating)
