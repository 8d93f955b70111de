"""Description joints → MuJoCo joints (hinge, slide, free; planar as slides + hinge), limits."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.description import WORLD_LINK, Joint
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

# Name of the free joint of a floating base (prefixed by the entity name after attach).
FREE_JOINT = "floating_base"


@dataclass(frozen=True)
class MjJointPlan:
    """One MuJoCo joint made for a description joint: its name, kind, home value, range.

    `urdf_joint` names the description joint it came from (None for the free joint).
    """

    name: str
    urdf_joint: str | None
    kind: str
    range: tuple[float, float] | None
    home: tuple[float, ...]


def add_joints(body: mujoco.MjsBody, joint: Joint | None, report: Report) -> list[MjJointPlan]:
    """Add the MuJoCo joint(s) for `joint` to `body`; returns them in qpos order."""
    if joint is None:
        return []
    for extra in joint.ignored:
        report.ignored(
            f"joint '{joint.name}' <{extra}>",
            "a ROS controller setting; Gazebo's physics does not use it either",
        )
    adder = _ADDERS.get(joint.kind)
    if adder is None:
        report.ignored(
            f"joint '{joint.name}'",
            f"type {joint.kind!r} is not a URDF joint type; the child is welded",
        )
        return []
    return adder(body, joint, report)


def _axis(joint: Joint) -> np.ndarray:
    axis = np.asarray(joint.axis, dtype=float)
    norm = np.linalg.norm(axis)
    return axis / norm if norm > 0 else np.array([1.0, 0.0, 0.0])


def _limited(
    body: mujoco.MjsBody, joint: Joint, kind: mujoco.mjtJoint, report: Report
) -> list[MjJointPlan]:
    """revolute (hinge) or prismatic (slide) with range, damping and friction."""
    import mujoco

    mj = body.add_joint(
        name=joint.name, type=kind, axis=_axis(joint).tolist(), pos=list(joint.anchor)
    )
    _dynamics(mj, joint)
    lower, upper = _bounds(joint)
    if lower is not None and upper is not None and lower < upper:
        mj.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        mj.range = np.array([lower, upper])
        home = min(max(0.0, lower), upper)
        return [MjJointPlan(joint.name, joint.name, joint.kind, (lower, upper), (home,))]
    mj.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    report.warn(
        f"joint '{joint.name}'",
        f"{joint.kind} joint without a usable <limit> "
        f"(lower={lower}, upper={upper}); left unlimited",
    )
    return [MjJointPlan(joint.name, joint.name, joint.kind, None, (0.0,))]


def _bounds(joint: Joint) -> tuple[float | None, float | None]:
    if joint.limit is None:
        return None, None
    return joint.limit.lower, joint.limit.upper


def _dynamics(mj: mujoco.MjsJoint, joint: Joint) -> None:
    if joint.dynamics is not None:
        mj.damping = np.array([joint.dynamics.damping, 0.0, 0.0])
        mj.frictionloss = joint.dynamics.friction


def _revolute(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    import mujoco

    return _limited(body, joint, mujoco.mjtJoint.mjJNT_HINGE, report)


def _prismatic(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    import mujoco

    return _limited(body, joint, mujoco.mjtJoint.mjJNT_SLIDE, report)


def _continuous(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    import mujoco

    mj = body.add_joint(
        name=joint.name,
        type=mujoco.mjtJoint.mjJNT_HINGE,
        axis=_axis(joint).tolist(),
        pos=list(joint.anchor),
    )
    mj.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    _dynamics(mj, joint)
    return [MjJointPlan(joint.name, joint.name, "continuous", None, (0.0,))]


def _planar(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    """Motion in the plane normal to the axis: two slides in the plane and a hinge about it."""
    import mujoco

    normal = _axis(joint)
    helper = np.array([1.0, 0, 0]) if abs(normal[0]) < 0.9 else np.array([0, 1.0, 0])
    u = np.cross(normal, helper)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    out = []
    for suffix, kind, axis in (
        ("x", mujoco.mjtJoint.mjJNT_SLIDE, u),
        ("y", mujoco.mjtJoint.mjJNT_SLIDE, v),
        ("yaw", mujoco.mjtJoint.mjJNT_HINGE, normal),
    ):
        mj = body.add_joint(
            name=f"{joint.name}_{suffix}", type=kind, axis=axis.tolist(), pos=list(joint.anchor)
        )
        _dynamics(mj, joint)
        out.append(MjJointPlan(mj.name, joint.name, "planar", None, (0.0,)))
    report.mapped(f"joint '{joint.name}'", "planar → two slides and a hinge about the normal")
    return out


def _floating(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    """A floating joint: a free joint on a top-level body, else three slides and a ball (MuJoCo
    free joints must be top-level)."""
    import mujoco

    if joint.parent == WORLD_LINK:
        return [add_free_joint(body, list(body.pos), list(body.quat), joint.name)]

    out = []
    for suffix, axis in (("x", (1, 0, 0)), ("y", (0, 1, 0)), ("z", (0, 0, 1))):
        mj = body.add_joint(
            name=f"{joint.name}_{suffix}", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=axis
        )
        out.append(MjJointPlan(mj.name, joint.name, "floating", None, (0.0,)))
    body.add_joint(
        name=f"{joint.name}_rot", type=mujoco.mjtJoint.mjJNT_BALL, pos=list(joint.anchor)
    )
    out.append(MjJointPlan(f"{joint.name}_rot", joint.name, "floating", None, (1.0, 0, 0, 0)))
    report.mapped(f"joint '{joint.name}'", "floating → three slides and a ball joint")
    return out


def _spherical(body: mujoco.MjsBody, joint: Joint, report: Report) -> list[MjJointPlan]:
    """Non-standard `spherical` (accepted by several parsers): a ball joint, unlimited."""
    import mujoco

    body.add_joint(name=joint.name, type=mujoco.mjtJoint.mjJNT_BALL, pos=list(joint.anchor))
    report.mapped(f"joint '{joint.name}'", "spherical → ball joint (limits not mapped)")
    return [MjJointPlan(joint.name, joint.name, "spherical", None, (1.0, 0.0, 0.0, 0.0))]


def add_free_joint(
    body: mujoco.MjsBody, pos: list[float], quat: list[float], name: str = FREE_JOINT
) -> MjJointPlan:
    """A named free joint; home = the body's pose (position [m], quaternion w-x-y-z)."""
    body.add_freejoint(name=name)
    source = None if name == FREE_JOINT else name
    return MjJointPlan(name, source, "free", None, (*map(float, pos), *map(float, quat)))


_ADDERS = {
    "revolute": _revolute,
    "continuous": _continuous,
    "prismatic": _prismatic,
    "planar": _planar,
    "floating": _floating,
    "spherical": _spherical,
}
