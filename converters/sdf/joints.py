"""SDF `<joint>` → description joint: frames, axis, limits, dynamics, springs, mimic.

The description's joint is URDF-shaped (child link frame in the parent link frame, axis in the
child frame); an SDF joint frame that is offset from its child link becomes the `anchor`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description import WORLD_LINK, Dynamics, Joint, JointExtension, Limit, Mimic
from converters.description.gazebo import Blob
from converters.description.transforms import vec3
from converters.gazebo.tags import to_xml
from converters.sdf.document import SdfContext, line_of
from converters.sdf.poses import MODEL_FRAME, PoseGraph, scoped

# SDF's "no limit" sentinel: |lower|, |upper| at or beyond this are unlimited (SDF default 1e16).
UNLIMITED = 1e15
# SDF joint types twin maps directly (to the description's URDF-style kinds).
KINDS = {
    "revolute": "revolute",
    "prismatic": "prismatic",
    "continuous": "continuous",
    "fixed": "fixed",
    "ball": "spherical",
}
# Types without a MuJoCo equivalent: mapped to the nearest kind, reported as approximated.
APPROXIMATED = {
    "universal": ("spherical", "a ball joint (2 rotational DOF become 3)"),
    "revolute2": ("spherical", "a ball joint (2 rotational DOF become 3)"),
    "screw": ("revolute", "a revolute joint (the thread's coupled translation is dropped)"),
    "gearbox": ("fixed", "welded (gearbox coupling is not simulated)"),
}


def read_joint(
    ctx: SdfContext, graph: PoseGraph, element: Any, prefix: str
) -> tuple[Joint, JointExtension]:
    """One joint and its Gazebo values (springs, limit softness).

    Raises:
        SDFError: unknown type, parent or child; a parent or child that names no link.
    """
    name = prefix + element.get("name", "")
    kind = _kind(ctx, element, name)
    parent = _link(ctx, graph, element, "parent", prefix)
    child = _link(ctx, graph, element, "child", prefix)
    if child == WORLD_LINK:
        raise ctx.error(element, "its child is the world", "make the world the parent")
    X_M_P = np.eye(4) if parent == WORLD_LINK else graph.pose(parent, element)
    X_M_C = graph.pose(child, element)
    X_C_J = np.linalg.inv(X_M_C) @ graph.pose(name, element)
    axis_element = element.find("axis")
    joint = Joint(
        name=name,
        kind=kind,
        parent=parent,
        child=child,
        origin=np.linalg.inv(X_M_P) @ X_M_C,
        axis=_axis(ctx, graph, axis_element, prefix, X_M_C, X_C_J),
        anchor=vec3(X_C_J[:3, 3]),
        limit=_limit(ctx, axis_element, kind),
        dynamics=_dynamics(ctx, axis_element),
        mimic=_mimic(ctx, axis_element, prefix),
    )
    return joint, _extension(ctx, element, axis_element, name)


def _kind(ctx: SdfContext, element: Any, name: str) -> str:
    sdf_type = element.get("type", "")
    if sdf_type in KINDS:
        return KINDS[sdf_type]
    if sdf_type in APPROXIMATED:
        kind, how = APPROXIMATED[sdf_type]
        ctx.report.approximated(f"joint '{name}'", f"type {sdf_type} → {how}")
        return kind
    allowed = ", ".join([*KINDS, *APPROXIMATED])
    raise ctx.error(
        element, f"type {sdf_type!r} is not an SDF joint type", f"use one of: {allowed}"
    )


def _link(ctx: SdfContext, graph: PoseGraph, element: Any, role: str, prefix: str) -> str:
    """The link a joint's parent/child names (a frame counts as the link it is attached to)."""
    written = ctx.text(element, role)
    if not written:
        raise ctx.error(element, f"has no <{role}>", f"name the {role} link in <{role}>")
    if written == WORLD_LINK:
        return WORLD_LINK
    return graph.link_of(scoped(written, prefix), element.find(role))


def _axis(
    ctx: SdfContext,
    graph: PoseGraph,
    axis: Any,
    prefix: str,
    X_M_C: np.ndarray,
    X_C_J: np.ndarray,
) -> tuple[float, float, float]:
    """The axis in the child link frame.

    `<xyz expressed_in="F">` names its frame, default the joint frame (sdformat honours it in
    every version: it upgrades older files); in 1.5-1.6 `<use_parent_model_frame>true` means
    the model frame, and wins (the 1.6 → 1.7 upgrade turns it into expressed_in="__model__");
    in 1.4 the axis is always in the model frame (the 1.4 → 1.5 upgrade adds that flag).
    """
    if axis is None or axis.find("xyz") is None:
        xyz, frame = np.array([0.0, 0.0, 1.0]), None
    else:
        xyz = np.asarray(ctx.vector(axis, "xyz", 3, (0.0, 0.0, 1.0)))
        frame = axis.find("xyz").get("expressed_in") or None
        version = ctx.version_of(axis)
        if version == "1.4" or (
            ctx.before_frames(axis) and ctx.flag(axis, "use_parent_model_frame", False)
        ):
            frame = MODEL_FRAME
    if frame is None:
        R_C_axis = X_C_J[:3, :3]
    else:
        R_C_axis = X_M_C[:3, :3].T @ graph.pose(scoped(frame, prefix), axis)[:3, :3]
    return vec3(R_C_axis @ xyz)


def _limit(ctx: SdfContext, axis: Any, kind: str) -> Limit:
    """The axis's `<limit>`; without one, SDF's defaults: no position, effort or speed bound."""
    limit = None if axis is None else axis.find("limit")
    if limit is None:
        return Limit()

    def bound(tag: str, default: float) -> float | None:
        value = ctx.number(limit, tag, default)
        return None if abs(value) >= UNLIMITED else value

    lower, upper = bound("lower", -1e16), bound("upper", 1e16)
    if kind == "continuous":
        lower = upper = None
    effort = ctx.number(limit, "effort", -1.0)
    velocity = ctx.number(limit, "velocity", -1.0)
    return Limit(lower, upper, effort if effort >= 0 else None, velocity if velocity >= 0 else None)


def _dynamics(ctx: SdfContext, axis: Any) -> Dynamics | None:
    dynamics = None if axis is None else axis.find("dynamics")
    if dynamics is None:
        return None
    return Dynamics(ctx.number(dynamics, "damping", 0.0), ctx.number(dynamics, "friction", 0.0))


def _mimic(ctx: SdfContext, axis: Any, prefix: str) -> Mimic | None:
    """SDFormat 1.11 `<axis><mimic joint="LEADER">`: follower = offset + multiplier · leader."""
    mimic = None if axis is None else axis.find("mimic")
    if mimic is None:
        return None
    leader = mimic.get("joint")
    if not leader:
        raise ctx.error(mimic, "has no joint attribute", "name the leader joint: joint='NAME'")
    multiplier = ctx.number(mimic, "multiplier", 1.0)
    return Mimic(scoped(leader, prefix), multiplier, ctx.number(mimic, "offset", 0.0))


def _extension(ctx: SdfContext, joint: Any, axis: Any, name: str) -> JointExtension:
    dynamics = None if axis is None else axis.find("dynamics")
    springs: dict[str, float] = {}
    if dynamics is not None:
        for tag in ("spring_stiffness", "spring_reference"):
            if dynamics.find(tag) is not None:
                springs[tag] = ctx.number(dynamics, tag, 0.0)
    limit = joint.find("physics/ode/limit")
    softness = {}
    if limit is not None:
        for tag in ("erp", "cfm"):
            if limit.find(tag) is not None:
                softness[f"stop_{tag}"] = ctx.number(limit, tag, 0.0)
    sensors = tuple(  # force_torque sensors, at the joint (sdformat: pose in the joint frame)
        Blob("sensor", s.get("name"), s.get("type"), to_xml(s), f"{ctx.source}:{line_of(s)}")
        for s in joint.findall("sensor")
    )
    return JointExtension(joint=name, **springs, **softness, sensors=sensors)
