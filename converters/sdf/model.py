"""SDF `<model>` → the neutral robot description (nested models flattened with `::` names).

Gazebo semantics that differ from URDF and are kept here: SDF fixed joints are not lumped (the
child stays its own link); a link that no joint moves floats on its own (each gets a free
joint), or is welded when the model is `<static>`; a joint to `world` anchors its child.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import replace
from types import MappingProxyType
from typing import Any

import numpy as np

from converters.description import (
    WORLD_LINK,
    Blob,
    Frame,
    GazeboExtensions,
    Inertial,
    Joint,
    JointExtension,
    Link,
    LinkExtension,
    RobotDescription,
)
from converters.gazebo.tags import to_xml
from converters.mjcf.inertia import from_inertial, problem
from converters.sdf.document import SdfContext, line_of
from converters.sdf.include import expand_includes
from converters.sdf.joints import read_joint
from converters.sdf.links import read_link
from converters.sdf.names import rename_clashes
from converters.sdf.poses import SEP, PoseGraph

# Model children twin reads elsewhere or on purpose leaves to Gazebo's other engines.
MODEL_IGNORED = ("allow_auto_disable", "enable_wind", "gripper")


def read_model(ctx: SdfContext, model: Any, text: str = "") -> RobotDescription:
    """One `<model>` (its `<include>`s expanded) as a robot description.

    Raises:
        SDFError: a model without links, bad names, poses, joints or values (file:line).
    """
    expand_includes(ctx, model)
    rename_clashes(ctx, model)
    graph = PoseGraph(ctx, model)
    if model.get("placement_frame"):  # an unknown frame is an error even where unused
        graph.pose(model.get("placement_frame"), model)
    scopes = list(_scopes(model, ""))
    links, ext_links, surfaces = [], {}, []
    for element, prefix in ((el, p) for m, p in scopes for el in m.findall("link")):
        link, extension, inline = read_link(ctx, graph, element, prefix)
        links.append(link)
        if extension != LinkExtension(link.name):
            ext_links[link.name] = extension
        surfaces.extend(inline)
    if not links:
        raise ctx.error(model, "has no <link>", "add at least one link")
    joints, loops, ext_joints, parent_of = [], [], {}, {}
    for element, prefix in ((el, p) for m, p in scopes for el in m.findall("joint")):
        joint, extension = read_joint(ctx, graph, element, prefix)
        if not _tree_edge(ctx, element, joint, parent_of):
            loops.append(joint)
            continue
        joints.append(joint)
        if _has_values(extension):
            ext_joints[joint.name] = extension
    static = ctx.flag(model, "static", False)
    names = [link.name for link in links]
    welded = _in_static_models(ctx, scopes, names)
    moved = {j.child for j in joints if j.kind != "fixed"}
    still = [n for n in names if (static or n in welded) and n not in moved]
    links = [_unused_inertia(ctx, link) if link.name in still else link for link in links]
    base, base_pose, anchors = _base(graph, names, joints, static, welded)
    _report_ignored(ctx, model)
    gazebo = GazeboExtensions(
        source=ctx.source,
        static=static,
        self_collide=ctx.flag(model, "self_collide", False),
        preserved_joints=frozenset(j.name for j in joints if j.kind == "fixed"),
        links=MappingProxyType(ext_links),
        joints=MappingProxyType(ext_joints),
        inline_surfaces=tuple(surfaces),
        plugins=tuple(_plugins(ctx, model)),
    )
    return RobotDescription(
        name=model.get("name", "model"),
        source=ctx.source,
        base_link=base,
        links=tuple(links),
        joints=tuple(anchors + joints),
        gazebo=gazebo,
        text=text,
        base_pose=base_pose,
        frames=_frames(graph),
        model_frame_site=True,
        loop_joints=tuple(loops),
    )


def _tree_edge(ctx: SdfContext, element: Any, joint: Joint, parent_of: dict[str, str]) -> bool:
    """Whether the joint is an edge of the link tree (MuJoCo's bodies are one); False for a
    joint that closes a loop (its child already has a parent joint, or is an ancestor of its
    parent): the body tree keeps the first joint and equalities close the loop.

    Raises:
        SDFError: a joint from a link to itself.
    """
    if joint.child == joint.parent:
        raise ctx.error(element, f"joins link '{joint.child}' to itself", "name two links")
    if joint.child in parent_of:
        return False
    link = joint.parent
    while link in parent_of:
        link = parent_of[link]
        if link == joint.child:
            return False
    parent_of[joint.child] = joint.parent
    return True


def _scopes(model: Any, prefix: str):
    """(model element, name prefix) for the model and every nested model, depth first."""
    yield model, prefix
    for nested in model.findall("model"):
        yield from _scopes(nested, prefix + nested.get("name", "") + SEP)


def _in_static_models(ctx: SdfContext, scopes: list, links: list[str]) -> set[str]:
    """Links of nested models that are `<static>` themselves (or inside a static one): Gazebo
    keeps them in place whatever their enclosing model does (a wrapper around included
    furniture, as the AWS worlds write)."""
    prefixes = [prefix for element, prefix in scopes[1:] if ctx.flag(element, "static", False)]
    return {name for name in links if any(name.startswith(p) for p in prefixes)}


def _base(
    graph: PoseGraph,
    links: list[str],
    joints: list[Joint],
    static: bool,
    welded: Collection[str] = (),
) -> tuple[str, np.ndarray, list[Joint]]:
    """The base link, its pose in the model frame, and joints that anchor extra roots.

    One root link and no joint to the world: that link is the base (floating unless static).
    Otherwise the world is the base: roots weld to it when the model is static or they belong
    to a static nested model (`welded`), else each gets a `floating` joint (a free joint in
    MuJoCo), as separate SDF bodies move freely.
    """
    children = {j.child for j in joints}
    roots = [name for name in links if name not in children]
    to_world = any(j.parent == WORLD_LINK for j in joints)
    if len(roots) == 1 and not to_world and roots[0] not in welded:
        return roots[0], graph.pose(roots[0]), []
    anchors = []
    for root in roots:
        kind = "fixed" if static or root in welded else "floating"
        anchors.append(Joint(f"{root}_{kind}", kind, WORLD_LINK, root, origin=graph.pose(root)))
    return WORLD_LINK, np.eye(4), anchors


def _unused_inertia(ctx: SdfContext, link: Link) -> Link:
    """A link that never moves (a static model's, and no joint moves it): a non-physical
    inertia does not matter, as Gazebo never uses it; it becomes no mass at all, said."""
    value = from_inertial(link.inertial)
    trouble = None if value is None else problem(value)
    if value is None or trouble is None or (value.mass == 0 and not np.any(value.tensor)):
        return link
    ctx.report.repaired(
        f"link '{link.name}' <inertial>",
        f"{trouble}; unused in a static model, so left out (the link never moves)",
    )
    return replace(link, inertial=Inertial(0.0, np.zeros((3, 3))))


def _frames(graph: PoseGraph) -> tuple[Frame, ...]:
    """Every `<frame>` as a pose in the link it is attached to."""
    out = []
    for name, node in graph.nodes.items():
        if node.kind != "frame":
            continue
        link = graph.link_of(name, node.element)
        X_M_L = np.eye(4) if link == WORLD_LINK else graph.pose(link)
        out.append(Frame(name, link, np.linalg.inv(X_M_L) @ graph.pose(name)))
    return tuple(out)


def _plugins(ctx: SdfContext, model: Any) -> list[Blob]:
    return [
        Blob("plugin", p.get("name"), p.get("filename"), to_xml(p), f"{ctx.source}:{line_of(p)}")
        for p in model.iter("plugin")
    ]


def _has_values(extension: JointExtension) -> bool:
    names = ("spring_stiffness", "spring_reference", "stop_erp", "stop_cfm")
    return bool(extension.sensors) or any(getattr(extension, n) is not None for n in names)


def _report_ignored(ctx: SdfContext, model: Any) -> None:
    name = model.get("name", "")
    for tag in MODEL_IGNORED:
        if model.find(tag) is None or (tag == "enable_wind" and not ctx.flag(model, tag, False)):
            continue  # no wind is what twin simulates: a false flag says nothing
        ctx.report.ignored(f"model '{name}' <{tag}>", "not simulated by twin")
