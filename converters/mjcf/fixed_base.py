"""`--fixed-base`: weld a robot's root link to the world, as a `world` link and a fixed joint do.

Gazebo users fix an arm whose description has no `world` link by adding one and a fixed joint
from it to the root link. The same in MuJoCo is a root body without a free joint: it is attached
where the model is placed (the spawn pose, or the origin in the exported scene) and only the
robot's own joints move.
"""

from __future__ import annotations

from dataclasses import replace

from converters.mjcf.lumping import WORLDBODY, BodyNode, BodyPlan
from converters.report import Report

OPTION = "--fixed-base"


def weld_base(plan: BodyPlan, report: Report) -> BodyPlan:
    """The plan with every floating root welded to the world, each weld reported.

    Floating roots are the root body of a floating plan (its free joint) and the bodies joined
    to the world by a `floating` joint (an SDF model's extra unjoined links, a URDF `floating`
    joint from a `world` link). A plan with neither is already fixed (a `world` link with fixed
    or moving joints, a `<static>` model) and is returned unchanged, which the report says.

    Args:
        plan: the body plan of `lumping.plan_bodies`.
        report: receives one line per welded root, or one saying nothing changed.
    """
    anchored = {
        node.name
        for node in plan.bodies
        if node.parent == WORLDBODY and node.joint is not None and node.joint.kind == "floating"
    }
    roots = sorted(anchored | ({plan.root_body} if plan.floating else set()))
    if not roots:
        report.ignored(OPTION, "the robot is already fixed to the world; nothing changed")
        return plan
    for root in roots:
        report.mapped(f"link '{root}'", f"root '{root}' welded to the world ({OPTION})")
    bodies = tuple(_welded(node) if node.name in anchored else node for node in plan.bodies)
    return replace(plan, bodies=bodies, floating=False)


def _welded(node: BodyNode) -> BodyNode:
    """The node with its joint to the world removed (a fixed joint keeps no joint)."""
    return replace(node, joint=None)
