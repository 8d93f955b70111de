"""URDF as XML, checked before any reader trusts it: well-formed, numbers parse, one tree.

Every failure names the file and the element (link, joint, attribute) and says how to fix it,
so a hand-edited file never reaches the reader or the builder with a value they would choke on.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from converters.errors import BadNumberError, MalformedXMLError, URDFStructureError

# Attributes holding numbers: tag → {attribute: count} (0 = any count ≥ 1).
NUMERIC_ATTRIBUTES: dict[str, dict[str, int]] = {
    "origin": {"xyz": 3, "rpy": 3},
    "axis": {"xyz": 3},
    "mass": {"value": 1},
    "inertia": {k: 1 for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")},
    "limit": {"lower": 1, "upper": 1, "effort": 1, "velocity": 1},
    "dynamics": {"damping": 1, "friction": 1},
    "box": {"size": 3},
    "cylinder": {"radius": 1, "length": 1},
    "capsule": {"radius": 1, "length": 1},
    "sphere": {"radius": 1},
    "mesh": {"scale": 3},
    "mimic": {"multiplier": 1, "offset": 1},
    "color": {"rgba": 4},
}


def parse_xml(text: str, source: str) -> ET.Element:
    """Parse XML text; malformed input → `MalformedXMLError` with file:line:column."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, column = exc.position
        message = str(exc).split(":")[0]
        raise MalformedXMLError(source, line, column + 1, message) from exc
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.startswith("{"):
            element.tag = element.tag.split("}", 1)[1]  # a default xmlns on <robot>
    return root


def _where(owner: ET.Element | None, element: ET.Element) -> str:
    if owner is None:
        return f"<{element.tag}>"
    return f"{owner.tag} '{owner.get('name', '?')}' <{element.tag}>"


def check_numbers(root: ET.Element, source: str) -> None:
    """Every numeric attribute of links/joints/materials parses as the right count of floats."""
    for owner in list(root):
        for element in owner.iter():
            for attr, count in NUMERIC_ATTRIBUTES.get(element.tag, {}).items():
                value = element.get(attr)
                if value is None:
                    continue
                expected = "a number" if count == 1 else f"{count} numbers"
                try:
                    numbers = [float(v) for v in value.split()]
                except ValueError as exc:
                    raise BadNumberError(
                        source, _where(owner, element), attr, value, expected
                    ) from exc
                if len(numbers) != count or not all(abs(v) < float("inf") for v in numbers):
                    raise BadNumberError(source, _where(owner, element), attr, value, expected)


def _unique_names(root: ET.Element, tag: str, source: str) -> list[str]:
    names: list[str] = []
    for element in root.findall(tag):
        name = element.get("name")
        if not name:
            raise URDFStructureError(source, f"a <{tag}>", "has no name", "give it a name")
        if name in names:
            raise URDFStructureError(
                source,
                f"{tag} '{name}'",
                "is defined twice",
                f"rename or remove one of the two <{tag}> elements",
            )
        names.append(name)
    return names


def check_tree(root: ET.Element, source: str) -> tuple[str, tuple[str, ...]]:
    """Links and joints form one tree, closed chains aside; returns its root link and the
    joints that close loops.

    As for SDF (`converters.sdf.model`), the first joint into a link is the tree's edge; a later
    joint into a link that already has a parent, or into an ancestor of its own parent, closes
    a loop (a four-bar's last bar, a parallel gripper's second link), which MuJoCo closes with
    equality constraints. urdfdom would keep one of the two joints and drop the other.

    Raises:
        URDFStructureError: duplicate names, unknown parent/child, several roots (a second
            parent that joins a link to nothing else names both joints), or no links.
    """
    links = _unique_names(root, "link", source)
    _unique_names(root, "joint", source)
    if not links:
        raise URDFStructureError(source, "<robot>", "has no <link>", "add at least one link")
    parent_of: dict[str, str] = {}
    loops: list[tuple[str, str, str]] = []  # (joint, parent, child)
    for joint in root.findall("joint"):
        parent, child = _joint_links(joint, links, source)
        if child == parent:
            raise URDFStructureError(
                source,
                f"joint '{joint.get('name')}'",
                f"joins link '{child}' to itself",
                "name two links",
            )
        if child in parent_of or _is_ancestor(child, parent, parent_of):
            loops.append((joint.get("name", ""), parent, child))
        else:
            parent_of[child] = parent
    roots = [link for link in links if link not in parent_of]
    if len(roots) != 1:
        _refuse_loose_loop(loops, parent_of, source)
        raise URDFStructureError(
            source,
            "links " + ", ".join(roots),
            f"the model has {len(roots)} root links (links with no parent joint)",
            "connect them with joints so exactly one root remains",
        )
    return roots[0], tuple(name for name, _, _ in loops)


def _root(link: str, parent_of: dict[str, str]) -> str:
    while link in parent_of:
        link = parent_of[link]
    return link


def _is_ancestor(link: str, of: str, parent_of: dict[str, str]) -> bool:
    while of in parent_of:
        of = parent_of[of]
        if of == link:
            return True
    return False


def _refuse_loose_loop(
    loops: list[tuple[str, str, str]], parent_of: dict[str, str], source: str
) -> None:
    """A second joint into a link whose parent the tree does not reach leaves two trees, not a
    loop: the likely slip is a joint with the wrong child, so say which (a loop inside one tree
    beside a stray link is not blamed; the roots' message names the stray link)."""
    for name, parent, child in loops:
        if child in parent_of and _root(parent, parent_of) != _root(child, parent_of):
            raise URDFStructureError(
                source,
                f"link '{child}'",
                f"is the child of two joints (parents '{parent_of[child]}' and '{parent}'), and "
                f"joint '{name}' does not close a loop: link '{parent}' is not joined to the rest",
                f"join link '{parent}' to the robot, or give joint '{name}' another child",
            )


def _joint_links(joint: ET.Element, links: list[str], source: str) -> tuple[str, str]:
    """The joint's parent and child links.

    Raises:
        URDFStructureError: either is missing or names no link of the robot.
    """
    found: list[str] = []
    for role in ("parent", "child"):
        element = joint.find(role)
        link = element.get("link") if element is not None else None
        if link not in links:
            raise URDFStructureError(
                source,
                f"joint '{joint.get('name')}'",
                f"{role} link {link!r} does not exist",
                f"use one of the links: {', '.join(links)}",
            )
        found.append(link)
    return found[0], found[1]


# URDF joint types (and `spherical`, which several parsers accept); anything else is refused.
JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar", "spherical")
# Shapes a URDF `<geometry>` may hold (`capsule` as ROS 2's urdfdom reads it), with the
# attributes each must have.
SHAPES = {
    "box": ("size",),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
    "mesh": ("filename",),
}


def check_kinds(root: ET.Element, source: str) -> None:
    """Every joint has a known type and every `<geometry>` exactly one known shape.

    urdfdom (and so Gazebo) refuses such files too; without this check a typo such as
    `type="fixd"` was welded silently and an emptied `<geometry/>` crashed the parser.

    Raises:
        URDFStructureError: naming the joint or link, the value, and the allowed ones.
    """
    for joint in root.findall("joint"):
        kind = joint.get("type")
        if kind not in JOINT_TYPES:
            raise URDFStructureError(
                source,
                f"joint '{joint.get('name', '?')}'",
                f"type {kind!r} is not a URDF joint type",
                f"use one of: {', '.join(JOINT_TYPES)}",
            )
    for link in root.findall("link"):
        for role in ("visual", "collision"):
            for index, element in enumerate(link.findall(role)):
                _check_geometry(element, f"link '{link.get('name', '?')}' <{role}> {index}", source)


def _check_geometry(element: ET.Element, where: str, source: str) -> None:
    geometry = element.find("geometry")
    if geometry is None:
        raise URDFStructureError(
            source, where, "has no <geometry>", "add <geometry> with one shape or remove it"
        )
    shapes = [child.tag for child in geometry]
    if len(shapes) != 1 or shapes[0] not in SHAPES:
        found = ", ".join(f"<{s}>" for s in shapes) or "nothing"
        raise URDFStructureError(
            source,
            f"{where} <geometry>",
            f"holds {found}",
            f"give exactly one of: {', '.join(f'<{s}>' for s in SHAPES)}",
        )
    shape = geometry[0]
    for attribute in SHAPES[shape.tag]:
        value = shape.get(attribute)
        if value is None or not value.strip():
            raise URDFStructureError(
                source,
                f"{where} <{shape.tag}>",
                f"has no {attribute}",
                f'write <{shape.tag} {attribute}="..."/>',
            )
        if shape.tag != "mesh" and any(float(v) <= 0 for v in value.split()):
            raise URDFStructureError(
                source,
                f"{where} <{shape.tag}>",
                f"{attribute}={value!r} is not positive",
                "give sizes in metres above 0",
            )
