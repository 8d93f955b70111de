"""Which links become MuJoCo bodies, and fixed-joint lumping as sdformat does it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from converters.description import WORLD_LINK, Joint, RobotDescription

# Name of the MuJoCo world body, as placements refer to it.
WORLDBODY = "world"


@dataclass(frozen=True)
class LinkPlacement:
    """Where a link ended up: its body and the link frame's pose in it (4×4)."""

    body: str
    T_body_link: np.ndarray


@dataclass(frozen=True)
class BodyNode:
    """One MuJoCo body to create.

    Attributes:
        name: body name (= its link).
        parent: parent body name (`WORLDBODY` for top-level bodies).
        T_parent_body: pose of this body in its parent body (4×4).
        joint: the description's joint that moves it (None for the root or a welded body).
    """

    name: str
    parent: str
    T_parent_body: np.ndarray
    joint: Joint | None


@dataclass(frozen=True)
class BodyPlan:
    """Bodies in creation order (parents first), link placements, lumped links, base kind."""

    bodies: tuple[BodyNode, ...]
    placements: dict[str, LinkPlacement]
    lumped: tuple[str, ...]
    root_body: str
    floating: bool


def plan_bodies(
    robot: RobotDescription,
    *,
    preserved: frozenset[str],
    keep_fixed: bool,
    static: bool,
) -> BodyPlan:
    """Decide bodies and placements, walking the tree from the base link in document order.

    A fixed joint's child is lumped into its parent's body (mass and geoms move there, the link
    stays as a site) unless the joint is in `preserved`, `keep_fixed` is set, or the parent is the
    `world` link. The base floats unless it is `world` (its children are then welded or jointed to
    the world) or the model is static.

    Args:
        robot: the description (its base link is the tree's root).
        preserved: fixed joints whose child must stay a body (Gazebo preserveFixedJoint).
        keep_fixed: keep every fixed joint as a welded body (`--keep-fixed`).
        static: Gazebo `<static>`: the base is welded to the world.
    """
    base_link = robot.base_link
    children = robot.children()
    placements: dict[str, LinkPlacement] = {}
    bodies: list[BodyNode] = []
    lumped: list[str] = []
    if base_link == WORLD_LINK:
        placements[base_link] = LinkPlacement(WORLDBODY, np.eye(4))
    else:
        placements[base_link] = LinkPlacement(base_link, np.eye(4))
        bodies.append(BodyNode(base_link, WORLDBODY, robot.base_pose, None))
    stack = [base_link]
    while stack:
        parent = stack.pop()
        here = placements[parent]
        for joint in children.get(parent, []):
            T_body_child = here.T_body_link @ joint.origin
            lump = joint.kind == "fixed" and not keep_fixed and joint.name not in preserved
            if lump and here.body != WORLDBODY:
                placements[joint.child] = LinkPlacement(here.body, T_body_child)
                lumped.append(joint.child)
            else:
                placements[joint.child] = LinkPlacement(joint.child, np.eye(4))
                moving = None if joint.kind == "fixed" else joint
                bodies.append(BodyNode(joint.child, here.body, T_body_child, moving))
        stack.extend(reversed([j.child for j in children.get(parent, [])]))
    root = base_link if base_link != WORLD_LINK else WORLDBODY
    floating = base_link != WORLD_LINK and not static
    return BodyPlan(tuple(_parents_first(bodies)), placements, tuple(lumped), root, floating)


def _parents_first(bodies: list[BodyNode]) -> list[BodyNode]:
    """Depth-first order (MuJoCo numbers bodies and joints depth-first)."""
    kids: dict[str, list[BodyNode]] = {}
    for body in bodies:
        kids.setdefault(body.parent, []).append(body)
    out: list[BodyNode] = []
    stack = list(reversed(kids.get(WORLDBODY, [])))
    while stack:
        body = stack.pop()
        out.append(body)
        stack.extend(reversed(kids.get(body.name, [])))
    return out
