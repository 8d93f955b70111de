"""URDF text → the neutral robot description, read from the XML tree that `xml_checks` vetted.

URDF is a thin schema over XML: once the tree is checked (numbers parse, one tree, known joint
types, one shape per `<geometry>` with its sizes), its links and joints are a few attribute
reads. twin used to hand the tree to yourdfpy for them; importing yourdfpy costs 0.95 s
(it imports trimesh, which imports scipy) for what these functions read directly. Mesh
references are resolved to files here, so later stages never see `package://`.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from converters.description import (
    Collision,
    Dynamics,
    Geometry,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mimic,
    RobotDescription,
    Visual,
)
from converters.description.transforms import pose_matrix
from converters.errors import PackageNotFoundError, ResourceNotFoundError, URDFStructureError
from converters.gazebo.blocks import parse_gazebo
from converters.isolated.bounded_child import READ_EVENT
from converters.resources.packages import PackageResolver
from converters.urdf.control import read_controls
from converters.urdf.xml_checks import check_kinds, check_numbers, check_tree, parse_xml

# Joint children that only ROS controllers read; reported as ignored by the builder.
CONTROLLER_ONLY = ("safety_controller", "calibration")
# URDF's default joint axis.
DEFAULT_AXIS = (1.0, 0.0, 0.0)
BOUNDED_KINDS = ("revolute", "prismatic")  # joints whose <limit> needs lower and upper


def parse_urdf(
    text: str,
    source: str,
    base_dir: Path,
    resolver: PackageResolver | None = None,
    *,
    as_written: bool = False,
) -> RobotDescription:
    """Parse and check URDF text into a robot description.

    Args:
        text: the URDF XML (after xacro).
        source: file name for messages.
        base_dir: directory relative mesh paths are taken from.
        resolver: finds `package://`, `model://` and relative mesh files (default: search
            the directories above `base_dir`).
        as_written: keep what Gazebo's URDF parser drops (see `converters.gazebo.blocks`).

    Raises:
        MalformedXMLError, BadNumberError, URDFStructureError, GazeboTagError,
        PackageNotFoundError, ResourceNotFoundError.
    """
    root = parse_xml(text, source)
    if root.tag != "robot":
        raise URDFStructureError(
            source,
            f"<{root.tag}>",
            "the root element is not <robot>",
            "give a URDF file (or a xacro that expands to one)",
        )
    check_numbers(root, source)
    base_link, loops = check_tree(root, source)
    check_kinds(root, source)
    # Tag errors first, as Gazebo reads the <gazebo> blocks before any mesh.
    gazebo = parse_gazebo(root, source, as_written=as_written)
    resolver = resolver or PackageResolver.create(Path(source) if source else None)
    reading = _LinkReader(_named_materials(root), base_dir, resolver)
    return RobotDescription(
        name=root.get("name") or "robot",
        source=source,
        base_link=base_link,
        links=tuple(reading.link(link) for link in root.findall("link")),
        joints=tuple(_joint(j) for j in root.findall("joint") if j.get("name", "") not in loops),
        loop_joints=tuple(_joint(j) for j in root.findall("joint") if j.get("name", "") in loops),
        gazebo=gazebo,
        actuated=_named_joints(root, ("transmission", "ros2_control")),
        text=text,
        controls=_controls(root, source),
    )


def _controls(root: ET.Element, source: str) -> tuple:
    """The joints' declared command interfaces (`urdf.control`), read only if the URDF has a
    `<ros2_control>` or `<transmission>`."""
    if root.find(".//ros2_control") is None and root.find(".//transmission") is None:
        return ()
    return read_controls(root, source)


def _floats(element: ET.Element | None, attribute: str, default: tuple[float, ...]) -> tuple:
    raw = element.get(attribute) if element is not None else None
    return default if raw is None else tuple(float(v) for v in raw.split())


def _number(element: ET.Element | None, attribute: str, default: float) -> float:
    value = _optional_number(element, attribute)
    return default if value is None else value


def _optional_number(element: ET.Element | None, attribute: str) -> float | None:
    raw = element.get(attribute) if element is not None else None
    return None if raw is None else float(raw)


def _link_of(joint: ET.Element, role: str) -> str:
    """The link a joint's `<parent>` or `<child>` names (`check_tree` made sure it exists)."""
    return joint.findall(role)[0].attrib["link"]


def _origin(owner: ET.Element) -> np.ndarray:
    """The `<origin xyz rpy>` of `owner` as 4×4 (R = Rz(yaw)·Ry(pitch)·Rx(roll))."""
    origin = owner.find("origin")
    xyz = _floats(origin, "xyz", (0.0, 0.0, 0.0))
    rpy = _floats(origin, "rpy", (0.0, 0.0, 0.0))
    return pose_matrix(xyz + rpy)


def _named_materials(root: ET.Element) -> dict[str, Material]:
    """Robot-level `<material>` definitions by name (later definitions win, as in urdfdom)."""
    out: dict[str, Material] = {}
    for element in root.findall("material"):
        name = element.get("name")
        if name:
            out[name] = _material_of(element)
    return out


def _material_of(element: ET.Element) -> Material:
    colour = element.find("color")
    texture = element.find("texture")
    rgba = _floats(colour, "rgba", ()) or None
    return Material(
        element.get("name"), rgba, texture.get("filename") if texture is not None else None
    )


class _LinkReader:
    """Reads `<link>` elements into description links: shapes, resolved meshes, materials."""

    def __init__(
        self, named: dict[str, Material], base_dir: Path, resolver: PackageResolver
    ) -> None:
        self.named = named
        self.base_dir = base_dir
        self.resolver = resolver

    def link(self, link: ET.Element) -> Link:
        name = link.get("name", "")
        visuals = tuple(self.visual(v, name, i) for i, v in enumerate(link.findall("visual")))
        collisions = tuple(
            Collision(_origin(c), self.geometry(c, name, "collision", i), c.get("name"))
            for i, c in enumerate(link.findall("collision"))
        )
        return Link(name, _inertial(link.find("inertial")), visuals, collisions)

    def visual(self, visual: ET.Element, link: str, index: int) -> Visual:
        """A `<visual>`; one whose mesh file or package is missing keeps no geometry and says
        why (`Visual.missing`): Gazebo spawns the robot without drawing it. A missing collision
        mesh still raises, as leaving it out would change the physics."""
        missing = None
        try:
            geometry: Geometry | None = self.geometry(visual, link, "visual", index)
        except (PackageNotFoundError, ResourceNotFoundError) as exc:
            geometry, missing = None, str(exc)
            _announce_missing(exc)
        material = self.material(visual)
        return Visual(_origin(visual), geometry, material, visual.get("name"), missing)

    def geometry(self, owner: ET.Element, link: str, role: str, index: int) -> Geometry:
        """The one shape of a `<visual>`/`<collision>` (xml_checks guarantees there is one)."""
        shape = owner.findall("geometry")[0][0]
        if shape.tag == "box":
            return Geometry("box", _floats(shape, "size", ()))
        if shape.tag in ("cylinder", "capsule"):
            return Geometry(
                shape.tag, (float(shape.attrib["radius"]), float(shape.attrib["length"]))
            )
        if shape.tag == "sphere":
            return Geometry("sphere", (float(shape.attrib["radius"]),))
        element = f"link '{link}' <{role}> {index} <mesh>"
        uri = shape.get("filename", "")
        path = self.resolver.resolve(uri, base_dir=self.base_dir, element=element)
        return Geometry("mesh", (), Path(path), uri, _scale(shape))

    def material(self, visual: ET.Element) -> Material | None:
        """A visual's material with its colour and texture filled in from the named ones."""
        element = visual.find("material")
        if element is None:
            return None
        own = _material_of(element)
        shared = self.named.get(own.name or "")
        if shared is None:
            return own
        return Material(own.name, own.rgba or shared.rgba, own.texture or shared.texture)


def _announce_missing(exc: Exception) -> None:
    """Name the files a missing mesh was sought at as read (`READ_EVENT`, with no content): a
    server's cached conversion depends on them, and is redone once one of them appears."""
    for path in getattr(exc, "tried", None) or [getattr(exc, "path", None)]:
        if path:
            sys.audit(READ_EVENT, str(path))


def _scale(mesh: ET.Element) -> tuple[float, float, float]:
    values = _floats(mesh, "scale", (1.0, 1.0, 1.0))
    if len(values) == 1:
        values = values * 3
    return (values[0], values[1], values[2])


def _inertial(element: ET.Element | None) -> Inertial | None:
    if element is None:
        return None
    moments = element.find("inertia")
    i = {k: _number(moments, k, 0.0) for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")}
    tensor = np.array(
        [
            [i["ixx"], i["ixy"], i["ixz"]],
            [i["ixy"], i["iyy"], i["iyz"]],
            [i["ixz"], i["iyz"], i["izz"]],
        ]
    )
    return Inertial(_number(element.find("mass"), "value", 0.0), tensor, _origin(element))


def _joint(joint: ET.Element) -> Joint:
    limit, dynamics, mimic = joint.find("limit"), joint.find("dynamics"), joint.find("mimic")
    return Joint(
        name=joint.get("name", ""),
        kind=joint.get("type", ""),
        parent=_link_of(joint, "parent"),
        child=_link_of(joint, "child"),
        origin=_origin(joint),
        axis=_floats(joint.find("axis"), "xyz", DEFAULT_AXIS),
        limit=_limit(limit, joint.get("type", "")),
        dynamics=None
        if dynamics is None
        else Dynamics(_number(dynamics, "damping", 0.0), _number(dynamics, "friction", 0.0)),
        mimic=None
        if mimic is None
        else Mimic(
            mimic.get("joint", ""),
            _number(mimic, "multiplier", 1.0),
            _number(mimic, "offset", 0.0),
        ),
        ignored=tuple(name for name in CONTROLLER_ONLY if joint.find(name) is not None),
    )


def _limit(limit: ET.Element | None, kind: str) -> Limit | None:
    """A joint's `<limit>`. ROS's URDF parser, which Gazebo reads URDF through, takes a missing
    `lower` or `upper` as 0, so a revolute or prismatic joint without them is held at 0."""
    if limit is None:
        return None
    lower, upper, effort, velocity = (
        _optional_number(limit, k) for k in ("lower", "upper", "effort", "velocity")
    )
    if kind not in BOUNDED_KINDS:
        return Limit(lower, upper, effort, velocity)
    defaulted = tuple(k for k, v in (("lower", lower), ("upper", upper)) if v is None)
    return Limit(
        0.0 if lower is None else lower,
        0.0 if upper is None else upper,
        effort,
        velocity,
        defaulted,
    )


def _named_joints(root: ET.Element, tags: tuple[str, ...]) -> tuple[str, ...]:
    """Joints named inside `<transmission>` then `<ros2_control>` blocks, in document order."""
    names: list[str] = []
    for tag in tags:
        for block in root.iter(tag):
            for joint in block.iter("joint"):
                name = joint.get("name")
                if name and name not in names:
                    names.append(name)
    return tuple(names)
