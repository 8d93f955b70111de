"""URDF text → the neutral robot description: yourdfpy reads links and joints, raw XML the rest.

yourdfpy parses the standard elements; what it drops (`<gazebo>`, `<transmission>`,
`<ros2_control>`, `<capsule>`) is read from the XML here. Mesh references are resolved to files
now, so later stages never see `package://` or the file's directory.
"""

from __future__ import annotations

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
from converters.errors import URDFStructureError
from converters.gazebo.blocks import parse_gazebo
from converters.resources.packages import PackageResolver
from converters.urdf.xml_checks import check_kinds, check_numbers, check_tree, parse_xml

# Joint children that only ROS controllers read; reported as ignored by the builder.
CONTROLLER_ONLY = ("safety_controller", "calibration")


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
    base_link = check_tree(root, source)
    check_kinds(root, source)
    capsules = _capsules_as_cylinders(root)
    model = _yourdfpy_robot(root, source)
    resolver = resolver or PackageResolver.create(Path(source) if source else None)
    named = {m.name: m for m in getattr(model, "materials", []) if getattr(m, "name", None)}
    gazebo = parse_gazebo(
        root, source, as_written=as_written
    )  # tag errors first, as Gazebo reads them before meshes
    reading = _LinkReader(capsules, named, base_dir, resolver)
    return RobotDescription(
        name=model.name,
        source=source,
        base_link=base_link,
        links=tuple(reading.link(link) for link in model.links),
        joints=tuple(_joint(joint) for joint in model.joints),
        gazebo=gazebo,
        actuated=_named_joints(root, ("transmission", "ros2_control")),
        text=text,
    )


def _yourdfpy_robot(root: ET.Element, source: str) -> object:
    import lxml.etree
    import yourdfpy

    try:
        return yourdfpy.URDF._parse_robot(lxml.etree.fromstring(ET.tostring(root, "unicode")))
    except (ValueError, KeyError, TypeError, lxml.etree.XMLSyntaxError) as exc:
        raise URDFStructureError(
            source, "<robot>", f"yourdfpy cannot read it: {exc}", "fix the element named above"
        ) from exc


def _pose(origin: object | None) -> np.ndarray:
    return np.eye(4) if origin is None else np.asarray(origin, dtype=float)


def _number(value: object | None, default: float | None = None) -> float | None:
    return default if value is None else float(value)


class _LinkReader:
    """Turns yourdfpy links into description links: shapes, resolved meshes, materials."""

    def __init__(
        self,
        capsules: set[tuple[str, str, int]],
        named: dict[str, object],
        base_dir: Path,
        resolver: PackageResolver,
    ) -> None:
        self.capsules = capsules
        self.named = named
        self.base_dir = base_dir
        self.resolver = resolver

    def link(self, link: object) -> Link:
        visuals = tuple(
            Visual(
                _pose(v.origin),
                self.geometry(v.geometry, link.name, "visual", i),
                self.material(v.material),
                v.name,
            )
            for i, v in enumerate(link.visuals)
        )
        collisions = tuple(
            Collision(_pose(c.origin), self.geometry(c.geometry, link.name, "collision", i), c.name)
            for i, c in enumerate(link.collisions)
        )
        return Link(link.name, _inertial(link.inertial), visuals, collisions)

    def geometry(
        self, geometry: object | None, link: str, role: str, index: int
    ) -> Geometry | None:
        """The shape of one `<visual>`/`<collision>`; None when it names no shape."""
        if geometry is None:
            return None
        if geometry.box is not None:
            return Geometry("box", tuple(float(v) for v in geometry.box.size))
        if geometry.cylinder is not None:
            shape = "capsule" if (link, role, index) in self.capsules else "cylinder"
            return Geometry(
                shape, (float(geometry.cylinder.radius), float(geometry.cylinder.length))
            )
        if geometry.sphere is not None:
            return Geometry("sphere", (float(geometry.sphere.radius),))
        if geometry.mesh is not None:
            element = f"link '{link}' <{role}> {index} <mesh>"
            uri = geometry.mesh.filename
            path = self.resolver.resolve(uri, base_dir=self.base_dir, element=element)
            return Geometry("mesh", (), Path(path), uri, _scale(geometry.mesh.scale))
        return None

    def material(self, material: object | None) -> Material | None:
        """A visual's material with its colour and texture filled in from the named ones."""
        if material is None:
            return None
        name = getattr(material, "name", None)
        colour = getattr(material, "color", None)
        texture = getattr(material, "texture", None)
        if (colour is None or texture is None) and name in self.named:
            shared = self.named[name]
            colour = colour if colour is not None else getattr(shared, "color", None)
            texture = texture if texture is not None else getattr(shared, "texture", None)
        rgba = tuple(float(c) for c in colour.rgba) if colour is not None else None
        return Material(name, rgba, getattr(texture, "filename", None))  # type: ignore[arg-type]


def _scale(value: object | None) -> tuple[float, float, float]:
    if value is None:
        return (1.0, 1.0, 1.0)
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    if arr.size == 1:
        arr = np.repeat(arr, 3)
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def _inertial(inertial: object | None) -> Inertial | None:
    if inertial is None:
        return None
    tensor = inertial.inertia if inertial.inertia is not None else np.zeros((3, 3))
    mass = _number(inertial.mass, 0.0)
    return Inertial(mass, np.asarray(tensor, dtype=float), _pose(inertial.origin))


def _joint(joint: object) -> Joint:
    limit = joint.limit
    dynamics = joint.dynamics
    mimic = joint.mimic
    axis = joint.axis if joint.axis is not None else (1.0, 0.0, 0.0)
    return Joint(
        name=joint.name,
        kind=joint.type,
        parent=joint.parent,
        child=joint.child,
        origin=_pose(joint.origin),
        axis=tuple(float(v) for v in axis),  # type: ignore[arg-type]
        limit=None
        if limit is None
        else Limit(
            _number(limit.lower),
            _number(limit.upper),
            _number(limit.effort),
            _number(limit.velocity),
        ),
        dynamics=None
        if dynamics is None
        else Dynamics(_number(dynamics.damping, 0.0), _number(dynamics.friction, 0.0)),
        mimic=None
        if mimic is None
        else Mimic(mimic.joint, _number(mimic.multiplier, 1.0), _number(mimic.offset, 0.0)),
        ignored=tuple(name for name in CONTROLLER_ONLY if getattr(joint, name, None) is not None),
    )


def _capsules_as_cylinders(root: ET.Element) -> set[tuple[str, str, int]]:
    """Rewrite `<capsule>` to `<cylinder>` (yourdfpy rejects capsules) and remember where."""
    found: set[tuple[str, str, int]] = set()
    for link in root.findall("link"):
        for role in ("visual", "collision"):
            for index, element in enumerate(link.findall(role)):
                capsule = element.find("geometry/capsule")
                if capsule is not None:
                    capsule.tag = "cylinder"
                    found.add((link.get("name"), role, index))
    return found


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
