"""An entity's tf edges in one compiled model: each frame anchored on a body (see `frames`)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from twin_cli.record.frames import (
    IDENTITY,
    SENSOR_SITE,
    WORLD_FRAME,
    Pose,
    Sources,
    UrdfJoint,
    sensor_frame,
    urdf_tree,
)
from twin_cli.world.entities import MODEL_SITE, EntityIndex, element_names
from twin_cli.world.pose import quat_multiply, rotate
from twin_cli.world.velocity_motors import is_rotor


@dataclass(frozen=True)
class Anchor:
    """Where a frame is: a body id and the frame's constant pose in that body."""

    body: int
    pose: Pose = IDENTITY


WORLD_ANCHOR = Anchor(0)


@dataclass(frozen=True)
class Edge:
    """One tf transform: parent and child frames, their anchors, whether it moves (`/tf`)."""

    parent: str
    child: str
    parent_anchor: Anchor
    child_anchor: Anchor
    moving: bool


@dataclass(frozen=True)
class EntityTree:
    """An entity's tf edges, its link frames (link → frame id), the frames of its odometry
    (`odom_frame` → `root_frame`) and each sensor's message frame."""

    edges: tuple[Edge, ...]
    links: dict[str, str]
    root_frame: str
    odom_frame: str
    sensor_frames: dict[str, str]


@dataclass(frozen=True)
class Names:
    """Body and site ids by element name, of one compiled model."""

    bodies: dict[str, int]
    sites: dict[str, int]


def model_names(model: mujoco.MjModel) -> Names:
    """The body and site ids of `model` by name."""
    return Names(
        {n: i for i, n in enumerate(element_names(model, model.name_bodyadr)) if n},
        {n: i for i, n in enumerate(element_names(model, model.name_siteadr)) if n},
    )


def anchor_of(model: mujoco.MjModel, names: Names, element: str) -> Anchor | None:
    """The anchor of the body or site named `element`, or None."""
    if element in names.bodies:
        return Anchor(names.bodies[element])
    site = names.sites.get(element)
    return None if site is None else _site_anchor(model, site)


def _site_anchor(model: mujoco.MjModel, site: int) -> Anchor:
    x, y, z = model.site_pos[site].tolist()
    w, qx, qy, qz = model.site_quat[site].tolist()
    return Anchor(int(model.site_bodyid[site]), ((x, y, z), (w, qx, qy, qz)))


def moves(model: mujoco.MjModel, parent: int, child: int) -> bool:
    """Whether body `child` moves against body `parent` (a joint or a mocap body between)."""
    body = child
    while body != parent and body != 0:
        if model.body_jntnum[body] > 0 or model.body_mocapid[body] >= 0:
            return True
        body = int(model.body_parentid[body])
    return body != parent


def entity_tree(
    model: mujoco.MjModel, names: Names, name: str, ix: EntityIndex, sources: Sources
) -> EntityTree:
    """The tf tree of entity `name` (its URDF's, else its model's body tree)."""
    tree = urdf_tree(sources.description) if sources.description else None
    if tree is not None:
        anchors, joints, roots = _urdf_links(model, names, name, *tree)
    else:
        anchors, joints, roots = _model_links(model, names, name, ix)
    frames = {link: sources.prefix + link for link in anchors}
    edges = [
        Edge(frames[j.parent], frames[j.child], anchors[j.parent], anchors[j.child],
             moves(model, anchors[j.parent].body, anchors[j.child].body))
        for j in joints
        if j.parent in anchors and j.child in anchors
    ]  # fmt: skip
    root_frame, odom_frame = WORLD_FRAME, WORLD_FRAME
    for root in roots:
        anchor = anchors.get(root, WORLD_ANCHOR)
        frames.setdefault(root, sources.prefix + root)
        root_frame, odom_frame, root_edges = _root_edges(
            model, ix, sources, frames[root], anchor, set(frames.values())
        )
        edges += root_edges
    sensors = {s.name: sensor_frame(s, frames, sources.prefix) for s in sources.sensors}
    edges += _sensor_edges(model, names, name, sources, frames, anchors, sensors)
    return EntityTree(tuple(edges), frames, root_frame, odom_frame, sensors)


def _root_edges(
    model: mujoco.MjModel,
    ix: EntityIndex,
    sources: Sources,
    frame: str,
    anchor: Anchor,
    taken: set[str],
) -> tuple[str, str, list[Edge]]:
    """world → the root link, or world → odometry frame → the root link of a mobile base.

    Returns the odometry's child frame (the root link's, or the one its drive names: then a
    fixed frame at the root link's, its parent in the tree), the odometry frame and the edges.
    """
    if frame == WORLD_FRAME:  # a URDF `world` link with no prefix: the world itself
        return frame, WORLD_FRAME, []
    moving = moves(model, 0, anchor.body)
    if sources.drive is None or ix.free_qpos < 0:
        return frame, WORLD_FRAME, [Edge(WORLD_FRAME, frame, WORLD_ANCHOR, anchor, moving)]
    odom, child = sources.drive
    edges = [Edge(WORLD_FRAME, odom, WORLD_ANCHOR, WORLD_ANCHOR, False)]
    if child and child not in (frame, odom, WORLD_FRAME) and child not in taken:
        edges.append(Edge(odom, child, WORLD_ANCHOR, anchor, moving))
        return child, odom, [*edges, Edge(child, frame, anchor, anchor, False)]
    return frame, odom, [*edges, Edge(odom, frame, WORLD_ANCHOR, anchor, moving)]


def _urdf_links(
    model: mujoco.MjModel, names: Names, name: str, links: tuple, joints: tuple
) -> tuple[dict[str, Anchor], list[UrdfJoint], list[str]]:
    """URDF links anchored on the model: a body, a lumped link's site, or (a dropped `world`
    link) placed from the origin of its fixed joint to an anchored child."""
    anchors = {}
    for link in links:
        anchor = anchor_of(model, names, f"{name}/{link}")
        if anchor is not None:
            anchors[link] = anchor
    for j in joints:
        if j.fixed and j.parent not in anchors and j.child in anchors:
            child = anchors[j.child]
            anchors[j.parent] = Anchor(child.body, compose(child.pose, invert(j.origin)))
    children = {j.child for j in joints}
    return anchors, list(joints), [link for link in links if link not in children]


def _model_links(
    model: mujoco.MjModel, names: Names, name: str, ix: EntityIndex
) -> tuple[dict[str, Anchor], list[UrdfJoint], list[str]]:
    """An entity without a URDF: its bodies, and its sites (SDF frames) fixed to them."""
    prefix, anchors, joints, roots = f"{name}/", {}, [], []
    link_of = {
        int(b): n.removeprefix(prefix)
        for n, b in names.bodies.items()
        if b in ix.bodies and not is_rotor(n)
    }
    for body, link in link_of.items():
        anchors[link] = Anchor(body)
        parent = int(model.body_parentid[body])
        if parent in link_of:
            joints.append(UrdfJoint(link_of[parent], link, False, IDENTITY))
        else:
            roots.append(link)
    for site_name, site in names.sites.items():
        link = site_name.removeprefix(prefix)
        body = int(model.site_bodyid[site])
        if body in link_of and link != MODEL_SITE and not link.startswith(SENSOR_SITE):
            anchors[link] = _site_anchor(model, site)
            joints.append(UrdfJoint(link_of[body], link, True, IDENTITY))
    return anchors, joints, roots


def _sensor_edges(
    model: mujoco.MjModel,
    names: Names,
    name: str,
    sources: Sources,
    frames: dict[str, str],
    anchors: dict[str, Anchor],
    sensors: dict[str, str],
) -> list[Edge]:
    """A sensor's own frame (one that is not a link's), fixed to its link."""
    edges, known = [], set(frames.values())
    for s in sources.sensors:
        frame = sensors[s.name]
        site = anchor_of(model, names, f"{name}/{SENSOR_SITE}{s.name}")
        if frame in known or s.link not in anchors or site is None:
            continue
        edges.append(Edge(frames[s.link], frame, anchors[s.link], site, False))
        known.add(frame)
    return edges


def static_pose(xpos: np.ndarray, xquat: np.ndarray, edge: Edge) -> Pose:
    """The child's pose in the parent frame, from body poses (any posture: it is fixed)."""
    parent = compose(_body_pose(xpos, xquat, edge.parent_anchor.body), edge.parent_anchor.pose)
    child = compose(_body_pose(xpos, xquat, edge.child_anchor.body), edge.child_anchor.pose)
    return compose(invert(parent), child)


def _body_pose(xpos: np.ndarray, xquat: np.ndarray, body: int) -> Pose:
    x, y, z = xpos[body].tolist()
    w, qx, qy, qz = xquat[body].tolist()
    return (x, y, z), (w, qx, qy, qz)


def compose(a: Pose, b: Pose) -> Pose:
    """The pose b expressed in a's parent: a ∘ b."""
    return _add(a[0], rotate(a[1], b[0])), quat_multiply(a[1], b[1])


def invert(a: Pose) -> Pose:
    conj = (a[1][0], -a[1][1], -a[1][2], -a[1][3])
    x, y, z = rotate(conj, a[0])
    return (-x, -y, -z), conj


def _add(a: tuple, b: tuple) -> tuple[float, float, float]:
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]
