"""Closed kinematic chains: each loop-closing joint becomes equality constraints.

MuJoCo's bodies form a tree, so the description keeps the first joint into a link in the tree
and sets every further joint into it aside as a loop joint. Each is closed here the way MuJoCo
closes chains, between the joint's child body (body1) and parent body (body2):

- revolute / continuous: two `connect` equalities (ball-joint constraints) at two points on the
  joint axis; together they remove every relative motion except the rotation about that axis;
- ball: one `connect` at the joint's anchor;
- fixed: one `weld`.

A `connect` between bodies takes its anchor in body1's frame and the matching point on body2
from the model's reference configuration (qpos0), where the file's poses already close the loop.
Sites would say the same with two extra named sites per point; the body form keeps the model
free of helper sites.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description import WORLD_LINK, Joint, RobotDescription
from converters.errors import URDFStructureError
from converters.mjcf.lumping import WORLDBODY, BodyPlan
from converters.report import Report

if TYPE_CHECKING:
    import mujoco

# [m] spacing of the second `connect` along a revolute loop joint's axis. The pair resists
# tilting of the axis with a lever of this length: a constraint error e [m] tilts the axis by
# e / spacing [rad]. 0.1 m is the order of a linkage bar (cm to m), so the tilt stays of the same
# order as the position error, while the point stays near the mechanism (a far point would
# amplify small pose errors of the file into large initial violations).
AXIS_SPACING = 0.1
HINGE_KINDS = ("revolute", "continuous")
BALL_KINDS = ("spherical", "ball")  # SDF "ball" reads as the description's "spherical"


def add_loop_equalities(
    spec: mujoco.MjSpec, robot: RobotDescription, plan: BodyPlan, report: Report
) -> int:
    """Add the equalities closing each loop joint of `robot`; return how many were added.

    Raises:
        URDFStructureError: a loop joint of a kind an equality cannot express (prismatic, ...).
    """
    added = 0
    for joint in robot.loop_joints:
        added += _close(spec, joint, plan, robot.source, report)
    return added


def _close(spec: mujoco.MjSpec, joint: Joint, plan: BodyPlan, source: str, report: Report) -> int:
    """Equalities for one loop joint, with their report line."""
    import mujoco

    child, T_child = _placement(plan, joint.child)
    parent, _ = _placement(plan, joint.parent)
    anchor = (T_child @ np.append(np.asarray(joint.anchor, dtype=float), 1.0))[:3]
    if joint.kind in HINGE_KINDS:
        axis = T_child[:3, :3] @ np.asarray(joint.axis, dtype=float)
        axis = axis / np.linalg.norm(axis)
        points = [anchor, anchor + AXIS_SPACING * axis]
        for i, point in enumerate(points):
            _connect(spec, f"{joint.name}_loop{i}", child, parent, point)
        report.mapped(
            f"joint '{joint.name}'",
            "closes a loop: two connect equalities on its axis, as MuJoCo closes chains",
        )
        return 2
    if joint.kind in BALL_KINDS:
        _connect(spec, f"{joint.name}_loop", child, parent, anchor)
        report.mapped(f"joint '{joint.name}'", "closes a loop: one connect equality at its anchor")
        return 1
    if joint.kind == "fixed":
        eq = spec.add_equality(
            name=f"{joint.name}_loop", type=mujoco.mjtEq.mjEQ_WELD, objtype=mujoco.mjtObj.mjOBJ_BODY
        )
        eq.name1, eq.name2 = child, parent
        data = np.zeros(len(eq.data))
        data[0:3] = anchor  # relpose zero: the pose at qpos0
        data[10] = 1.0  # torquescale
        eq.data = data
        report.mapped(f"joint '{joint.name}'", "closes a loop: one weld equality")
        return 1
    raise URDFStructureError(
        source,
        f"joint '{joint.name}'",
        f"a {joint.kind} joint closes a loop into link '{joint.child}', which already has a "
        "parent joint; MuJoCo closes loops only at revolute, continuous, ball (spherical) "
        "or fixed joints",
        "list a revolute, ball or fixed joint of the loop last, so it closes the loop, "
        "or remove the joint",
    )


def _connect(spec: mujoco.MjSpec, name: str, body1: str, body2: str, anchor: np.ndarray) -> None:
    """One `connect` between two bodies at `anchor` (in body1's frame)."""
    import mujoco

    eq = spec.add_equality(
        name=name, type=mujoco.mjtEq.mjEQ_CONNECT, objtype=mujoco.mjtObj.mjOBJ_BODY
    )
    eq.name1, eq.name2 = body1, body2
    data = np.zeros(len(eq.data))
    data[0:3] = anchor
    eq.data = data


def _placement(plan: BodyPlan, link: str) -> tuple[str, np.ndarray]:
    """(body, pose of the link frame in it); the world link is the world body."""
    if link == WORLD_LINK:
        return WORLDBODY, np.eye(4)
    placement = plan.placements[link]
    return placement.body, placement.T_body_link
