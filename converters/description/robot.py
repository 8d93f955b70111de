"""The neutral robot description: links, joints and shapes as every format reader produces them.

Format-free: the URDF reader (and the SDF reader next) fill these records; lumping, the MuJoCo
builder and the Gazebo stage read them and never see XML. Units are SI, poses are 4×4 transforms
of the child frame in its parent (link frame for inertials, visuals and collisions; parent link
frame for joints), and mesh files are already resolved to paths on disk.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from converters.description.control import JointControl
from converters.description.gazebo import GazeboExtensions

# A link of this name is the world itself: a joint to it fixes (or moves) the model against the
# world instead of letting the base float (sdformat's URDF reader, Gazebo's spawn).
WORLD_LINK = "world"
# The site a converted model carries at its frame where that is not its root link's (SDF's
# `__model__`): poses, gz-sim's model-frame commands and tf are given in it.
MODEL_SITE = "__model__"

# Shapes a geometry can have; `size` below gives each one's numbers.
SHAPES = ("box", "cylinder", "sphere", "capsule", "ellipsoid", "plane", "mesh")

# Joint kinds: URDF's six, plus `spherical`, which several parsers accept.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar", "spherical")


def identity() -> np.ndarray:
    """A fresh 4×4 identity pose (each record owns its array)."""
    return np.eye(4)


@dataclass(frozen=True)
class Geometry:
    """One shape in its own frame.

    Attributes:
        shape: one of `SHAPES`.
        size: [m] box edge lengths (x, y, z); cylinder and capsule (radius, length);
            sphere (radius,); ellipsoid radii (a, b, c); plane extent (x, y), normal +z;
            empty for a mesh.
        mesh: the resolved mesh file (meshes only); uri: the reference as the file wrote it.
        scale: the mesh's per-axis scale (unitless).
    """

    shape: str
    size: tuple[float, ...] = ()
    mesh: Path | None = None
    uri: str | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Material:
    """A visual's material, already resolved against the description's named materials.

    `rgba` in [0, 1] (None when only a texture or a name is known); `texture` is a file name.
    """

    name: str | None = None
    rgba: tuple[float, float, float, float] | None = None
    texture: str | None = None


@dataclass(frozen=True)
class Visual:
    """A drawn shape of a link: pose in the link frame, geometry (None when empty), material.

    `missing` is set when the mesh file (or its package) was not found: the geometry is then
    None, as Gazebo draws nothing for it, and `missing` is the resolver's message (what was
    looked for, where, and the fix), reported by `references.missing_visuals`.
    """

    origin: np.ndarray = field(default_factory=identity)
    geometry: Geometry | None = None
    material: Material | None = None
    name: str | None = None
    missing: str | None = None


@dataclass(frozen=True)
class Collision:
    """A colliding shape of a link: pose in the link frame and geometry (None when empty).

    Its surface (friction, contact stiffness) is Gazebo's business: `GazeboExtensions.surface_of`.
    """

    origin: np.ndarray = field(default_factory=identity)
    geometry: Geometry | None = None
    name: str | None = None


@dataclass(frozen=True)
class Inertial:
    """Mass [kg] and inertia tensor (3, 3) [kg·m²] about the centre of mass, in the frame
    `origin` (4×4, in the link frame) whose position is the centre of mass."""

    mass: float
    inertia: np.ndarray
    origin: np.ndarray = field(default_factory=identity)


@dataclass(frozen=True)
class Link:
    """A rigid body of the description; `inertial` is None when the file gives none."""

    name: str
    inertial: Inertial | None = None
    visuals: tuple[Visual, ...] = ()
    collisions: tuple[Collision, ...] = ()


@dataclass(frozen=True)
class Limit:
    """Joint limits: position lower/upper [rad or m], effort [N·m or N], velocity [rad/s or m/s].

    `defaulted` names the bounds the file left out and its format's default filled in (URDF
    reads a missing `lower` or `upper` of a revolute or prismatic joint as 0)."""

    lower: float | None = None
    upper: float | None = None
    effort: float | None = None
    velocity: float | None = None
    defaulted: tuple[str, ...] = ()


@dataclass(frozen=True)
class Dynamics:
    """Joint damping [N·m·s/rad or N·s/m] and dry friction [N·m or N]."""

    damping: float = 0.0
    friction: float = 0.0


@dataclass(frozen=True)
class Mimic:
    """This joint follows `joint`: position = offset + multiplier · leader position."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    """A joint from `parent` to `child`.

    Attributes:
        kind: one of `JOINT_TYPES` (anything else is welded, with a report line).
        origin: pose of the child link frame in the parent link frame at zero position (4×4).
        axis: the motion axis in the child frame (not normalised here).
        anchor: [m] the point the joint turns about, in the child frame (URDF: its origin;
            SDF: the joint frame's position).
        ignored: child elements no physics engine uses (`safety_controller`, `calibration`).
    """

    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray = field(default_factory=identity)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    anchor: tuple[float, float, float] = (0.0, 0.0, 0.0)
    limit: Limit | None = None
    dynamics: Dynamics | None = None
    mimic: Mimic | None = None
    ignored: tuple[str, ...] = ()


@dataclass(frozen=True)
class Frame:
    """A named frame fixed to a link (SDF `<frame>`): kept as a site so it can be addressed."""

    name: str
    link: str
    pose: np.ndarray = field(default_factory=identity)


@dataclass(frozen=True)
class RobotDescription:
    """One robot, independent of the file format it was written in.

    Attributes:
        name: the robot's (model's) name.
        source: the description file, for messages.
        base_link: the one link that is nobody's child (`WORLD_LINK` for a world-anchored model).
        links, joints: in document order.
        actuated: joints the file's control tags name (URDF `<transmission>`, `<ros2_control>`),
            in document order; empty when it has none.
        gazebo: Gazebo's typed values (surfaces, link and joint flags, plugins, sensors).
        text: the description as text (URDF after xacro), for tools that want the original.
        base_pose: the base link's pose in the model frame (URDF: identity; SDF: its `<pose>`).
        frames: named frames fixed to links (SDF `<frame>`).
        model_frame_site: mark the model frame with a `__model__` site when it is not the root
            link's frame (SDF), so a running world can report the model's pose as Gazebo does.
        controls: the command interfaces each `<ros2_control>`/`<transmission>` joint declares.
        base_dir: where the file's relative paths start (its folder; for a text description,
            the folder it was sent from); empty: the folder of `source`.
        loop_joints: joints into a link that already has a parent joint (closed chains);
            kept out of `joints` so the links stay a tree, closed by equality constraints.
    """

    name: str
    source: str
    base_link: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    gazebo: GazeboExtensions
    actuated: tuple[str, ...] = ()
    text: str = ""
    base_pose: np.ndarray = field(default_factory=identity)
    frames: tuple[Frame, ...] = ()
    model_frame_site: bool = False
    controls: tuple[JointControl, ...] = ()
    base_dir: str = ""
    loop_joints: tuple[Joint, ...] = ()

    def link(self, name: str) -> Link:
        """The link called `name` (KeyError when there is none)."""
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)

    def children(self) -> dict[str, list[Joint]]:
        """Joints by parent link, in document order."""
        out: dict[str, list[Joint]] = {}
        for joint in self.joints:
            out.setdefault(joint.parent, []).append(joint)
        return out

    def walk(self) -> Iterator[tuple[int, str, Joint | None]]:
        """Depth-first (depth, link, joint into it) from the base link, children in file order."""
        children = self.children()
        stack: list[tuple[int, str, Joint | None]] = [(0, self.base_link, None)]
        while stack:
            depth, link, joint = stack.pop()
            yield depth, link, joint
            for child in reversed(children.get(link, [])):
                stack.append((depth + 1, child.child, child))
