"""Description joints → MuJoCo joints (hinge, slide, free; planar as slides + hinge), limits.

A revolute or prismatic joint whose lower limit equals its upper limit cannot move in Gazebo
(ODE and DART both hold it at that value). MuJoCo refuses a zero-width range, so such a joint
stays a MuJoCo joint, unlimited, held at the value by a stiff joint equality: it keeps its name
for controllers, sensors and the tf tree, and its home value is the locked value.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from converters.description import WORLD_LINK, Joint
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

    from converters.description import RobotDescription

# Name of the free joint of a floating base (prefixed by the entity name after attach).
FREE_JOINT = "floating_base"

# A locked joint's equality. solref's time constant [s] is below any timestep, so MuJoCo's
# refsafe raises it to 2 · timestep, the stiffest stable setting; solimp's impedance 0.9999 at
# every violation (MuJoCo's default: 0.9 to 0.95) leaves 1e-4 of a soft constraint's give.
# Measured: a 1 kg link 0.5 m out on a locked hinge holds within 8e-9 rad for 2 s at a 1 ms
# step, 2.4e-8 rad at 2 ms and 1.5e-7 rad at 5 ms.
LOCK_SOLREF = (1e-6, 1.0)
LOCK_SOLIMP = (0.9999, 0.9999, 0.001, 0.5, 2.0)
LOCKABLE = ("revolute", "prismatic")
UNITS = {"revolute": "rad", "prismatic": "m"}


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
    locked = locked_value(joint)
    _report_defaulted(joint, report)
    if locked is not None:
        mj.limited = mujoco.mjtLimited.mjLIMITED_FALSE
        report.mapped(
            f"joint '{joint.name}'",
            f"locked at {locked:g} {UNITS[joint.kind]} (lower = upper), as Gazebo does",
        )
        return [MjJointPlan(joint.name, joint.name, joint.kind, (locked, locked), (locked,))]
    if lower is not None and upper is not None and lower < upper:
        mj.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        mj.range = np.array([lower, upper])
        home = min(max(0.0, lower), upper)
        return [MjJointPlan(joint.name, joint.name, joint.kind, (lower, upper), (home,))]
    mj.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    unusable = _unusable_limit(joint, lower, upper)
    if unusable:
        problem, fix = unusable
        report.warn(f"joint '{joint.name}'", f"{problem}; left unlimited; {fix}")
    return [MjJointPlan(joint.name, joint.name, joint.kind, None, (0.0,))]


def _report_defaulted(joint: Joint, report: Report) -> None:
    """Says which bounds URDF's default of 0 filled in: a joint held at 0, or turning one way
    only, is rarely what the author meant, though it is what Gazebo loads."""
    if joint.limit is None or not joint.limit.defaulted:
        return
    missing = " and ".join(joint.limit.defaulted)
    report.warn(
        f"joint '{joint.name}'",
        f"<limit> has no {missing}: URDF reads a missing bound as 0, so the range is "
        f"[{joint.limit.lower:g}, {joint.limit.upper:g}] {UNITS[joint.kind]}, as in Gazebo; "
        'give lower and upper, or use type="continuous" for a joint without limits',
    )


def _unusable_limit(
    joint: Joint, lower: float | None, upper: float | None
) -> tuple[str, str] | None:
    """(Why a joint's limits cannot bound it, the fix), or None when it is unlimited as its file
    says (an SDF axis without `<limit>`, or with SDF's ±1e16, is unlimited by default)."""
    unit = UNITS[joint.kind]
    if joint.limit is None:
        return (
            f"{joint.kind} joint without <limit>: URDF requires one (ROS's URDF parser "
            "refuses the file)",
            "give lower, upper, effort and velocity",
        )
    if lower is None and upper is None:
        return None
    if lower is None or upper is None:
        side, value = ("upper", upper) if lower is None else ("lower", lower)
        return (
            f"only a {side} limit ({value:g} {unit}): MuJoCo limits both sides or none",
            "give the other bound",
        )
    return f"lower {lower:g} > upper {upper:g} {unit}", "swap them"


def locked_value(joint: Joint) -> float | None:
    """The value [rad or m] a revolute or prismatic joint is held at (lower = upper), or None."""
    lower, upper = _bounds(joint)
    if joint.kind in LOCKABLE and lower is not None and lower == upper:
        return lower
    return None


def add_joint_locks(spec: mujoco.MjSpec, robot: RobotDescription) -> int:
    """Hold each locked joint at its value with a joint equality; returns how many.

    MuJoCo's joint equality with no second joint holds `joint1 - qpos0 = polycoef[0]`, and
    qpos0 is 0 for these hinges and slides, so polycoef[0] is the locked value itself.
    """
    import mujoco

    count = 0
    for joint in robot.joints:
        value = locked_value(joint)
        if value is None or spec.joint(joint.name) is None:
            continue
        equality = spec.add_equality(name=f"lock_{joint.name}")
        equality.type = mujoco.mjtEq.mjEQ_JOINT
        equality.objtype = mujoco.mjtObj.mjOBJ_JOINT
        equality.name1 = joint.name
        equality.data[:5] = [value, 0.0, 0.0, 0.0, 0.0]
        equality.solref = np.array(LOCK_SOLREF)
        equality.solimp = np.array(LOCK_SOLIMP)
        count += 1
    return count


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
