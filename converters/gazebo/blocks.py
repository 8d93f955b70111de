"""Read `<gazebo>` blocks and inline `<collision><surface>` of an expanded URDF into typed values.

Follows sdformat's URDF reader (`parser_urdf.cc`, `ParseSDFExtension`): a block without
`reference` applies to the model, `reference="X"` to the link or joint named X; a value is the
element text or its `value="..."` attribute; a tag written twice keeps the later value. Known tags
become typed fields (`mu1: float | None`, never flag pairs); unknown children are kept as blobs.
Nothing here touches MuJoCo: `converters.gazebo.apply` turns these values into spec settings.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from types import MappingProxyType
from typing import Any

from converters.description.gazebo import (
    Blob,
    GazeboExtensions,
    InlineSurface,
    JointExtension,
    LinkExtension,
    Surface,
    TagSource,
)
from converters.gazebo.tags import (
    JOINT_TAGS,
    LINK_TAGS,
    SURFACE_PATHS,
    ValueContext,
    children_of,
    read_bool,
    read_float,
    text_of,
    to_xml,
)


def _blob(el: ET.Element, ctx: ValueContext) -> Blob:
    kind = el.get("type") if el.tag == "sensor" else el.get("filename")
    block = f"<gazebo reference='{ctx.reference}'>" if ctx.reference else "<gazebo>"
    return Blob(str(el.tag), el.get("name"), kind, to_xml(el), f"{ctx.source}: {block}")


def read_surface(el: ET.Element, ctx: ValueContext) -> tuple[Surface, list[TagSource]]:
    """Read an SDF `<collision>`-like element (children `surface`, `max_contacts`, ...).

    Args:
        el: the element that holds `<surface>` (a URDF `<collision>` or a `<gazebo><collision>`).
        ctx: source and reference for error messages.

    Returns:
        The surface and the source of each value found.
    """
    values: dict[str, Any] = {}
    sources: list[TagSource] = []
    for path, (name, reader) in SURFACE_PATHS.items():
        found = el.find(path)
        if found is not None:
            raw = text_of(found)
            values[name] = reader(ctx, path, raw)
            sources.append(TagSource(ctx.reference, path, raw))
    return Surface(**values), sources


class _Acc:
    """Values gathered for one reference across all its `<gazebo>` blocks (later ones win)."""

    def __init__(self) -> None:
        self.surface: dict[str, Any] = {}
        self.link: dict[str, Any] = {}
        self.joint: dict[str, Any] = {}
        self.block_surface = Surface()
        self.sensors: list[Blob] = []
        self.blobs: list[Blob] = []
        self.sources: list[TagSource] = []


def _read_reference_child(
    child: ET.Element, acc: _Acc, ctx: ValueContext, is_link: bool, is_joint: bool
) -> None:
    tag = str(child.tag)
    raw = text_of(child)
    if tag in LINK_TAGS and (is_link or not is_joint):
        group, name, reader = LINK_TAGS[tag]
        (acc.surface if group == "surface" else acc.link)[name] = reader(ctx, tag, raw)
    elif tag in JOINT_TAGS and (is_joint or not is_link):
        name, reader = JOINT_TAGS[tag]
        acc.joint[name] = reader(ctx, tag, raw)
    elif tag == "collision":
        surface, sources = read_surface(child, ctx)
        acc.block_surface = acc.block_surface.overridden_by(surface)
        acc.sources.extend(sources)
        return
    elif tag == "visual":
        acc.link["visual_rgba"] = _read_visual_rgba(child, ctx)
    elif tag == "sensor":
        acc.sensors.append(_blob(child, ctx))
    else:
        acc.blobs.append(_blob(child, ctx))
        raw = "<blob>"
    acc.sources.append(TagSource(ctx.reference, tag, raw))


def _read_visual_rgba(
    el: ET.Element, ctx: ValueContext
) -> tuple[float, float, float, float] | None:
    diffuse = el.find("material/diffuse")
    if diffuse is None:
        return None
    parts = [read_float(ctx, "visual/material/diffuse", p) for p in text_of(diffuse).split()]
    if len(parts) not in (3, 4):
        raise ctx.fail("visual/material/diffuse", text_of(diffuse), "three numbers")
    return (parts[0], parts[1], parts[2], parts[3] if len(parts) == 4 else 1.0)


def _read_model_block(block: ET.Element, ctx: ValueContext, model: dict[str, Any]) -> None:
    for child in children_of(block):
        tag, raw = str(child.tag), text_of(child)
        if tag == "static":
            model["static"] = read_bool(ctx, tag, raw)
        elif tag in ("self_collide", "selfCollide"):
            model["self_collide"] = read_bool(ctx, tag, raw)
        elif tag == "plugin":
            model["plugins"].append(_blob(child, ctx))
        else:
            model["blobs"].append(_blob(child, ctx))
        model["sources"].append(TagSource("", tag, raw if len(child) == 0 else "<blob>"))


def parse_gazebo(root: ET.Element, source: str, *, as_written: bool = False) -> GazeboExtensions:
    """Read every `<gazebo>` block and inline `<collision><surface>` of an expanded URDF.

    By default the values end up where Gazebo's own URDF parser (sdformat) puts them: an inline
    `<surface>` is dropped and a named `<collision>` gets none of its link's surface values;
    `as_written` applies what the file says instead.

    Args:
        root: the `<robot>` element after xacro expansion.
        source: the file name used in error messages.
        as_written: apply inline surfaces and link values to named collisions.

    Returns:
        The typed extensions of the model, its links and its joints.

    Raises:
        GazeboTagError: a value is not a number/boolean/vector where the tag needs one; the
            message names the file, the reference, the tag and the value.
    """
    link_names = {el.get("name", "") for el in root.findall("link")}
    joint_types = {el.get("name", ""): el.get("type", "") for el in root.findall("joint")}
    model: dict[str, Any] = {"plugins": [], "blobs": [], "sources": []}
    accs: dict[str, _Acc] = {}
    unresolved: list[str] = []
    for block in root.findall("gazebo"):
        reference = block.get("reference")
        ctx = ValueContext(source, reference or "")
        if not reference:
            _read_model_block(block, ctx, model)
            continue
        is_link, is_joint = reference in link_names, reference in joint_types
        if not (is_link or is_joint) and reference not in unresolved:
            unresolved.append(reference)
        acc = accs.setdefault(reference, _Acc())
        for child in children_of(block):
            _read_reference_child(child, acc, ctx, is_link, is_joint)
    links = {
        ref: _link_extension(ref, acc)
        for ref, acc in accs.items()
        if ref in link_names or ref not in joint_types
    }
    joints = {ref: _joint_extension(ref, acc) for ref, acc in accs.items() if ref in joint_types}
    inline = _inline_surfaces(root, source)
    return GazeboExtensions(
        source=source,
        static=model.get("static", False),
        self_collide=model.get("self_collide", False),
        preserved_joints=_preserved(joints, joint_types),
        links=MappingProxyType(links),
        joints=MappingProxyType(joints),
        inline_surfaces=inline if as_written else (),
        dropped_surfaces=() if as_written else inline,
        named_collisions=frozenset() if as_written else _named_collisions(root),
        plugins=tuple(model["plugins"]),
        model_blobs=tuple(model["blobs"]),
        unresolved=tuple(unresolved),
        sources=tuple(model["sources"]),
    )


def _link_extension(link: str, acc: _Acc) -> LinkExtension:
    surface = acc.block_surface.overridden_by(Surface(**acc.surface))
    return LinkExtension(
        link=link,
        surface=surface,
        sensors=tuple(acc.sensors),
        blobs=tuple(acc.blobs),
        sources=tuple(acc.sources),
        **acc.link,
    )


def _joint_extension(joint: str, acc: _Acc) -> JointExtension:
    return JointExtension(
        joint=joint,
        sensors=tuple(acc.sensors),  # force_torque sensors sit on joints
        blobs=tuple(acc.blobs),
        sources=tuple(acc.sources),
        **acc.joint,
    )


def _preserved(joints: dict[str, JointExtension], joint_types: dict[str, str]) -> frozenset[str]:
    return frozenset(
        name
        for name, ext in joints.items()
        if joint_types.get(name) == "fixed"
        and (ext.preserve_fixed_joint or ext.disable_fixed_joint_lumping)
    )


def _inline_surfaces(root: ET.Element, source: str) -> tuple[InlineSurface, ...]:
    found: list[InlineSurface] = []
    for link in root.findall("link"):
        name = link.get("name", "")
        for index, collision in enumerate(link.findall("collision")):
            if collision.find("surface") is None:
                continue
            surface, _ = read_surface(collision, ValueContext(source, name))
            found.append(InlineSurface(name, index, surface))
    return tuple(found)


def _named_collisions(root: ET.Element) -> frozenset[tuple[str, int]]:
    """(link, index) of every `<collision name="...">`: sdformat matches a link's `<gazebo>`
    surface values only to the collision names it generates itself, never to a given name."""
    return frozenset(
        (link.get("name", ""), index)
        for link in root.findall("link")
        for index, collision in enumerate(link.findall("collision"))
        if collision.get("name")
    )
