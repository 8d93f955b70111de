"""SDF `<link>` → description link: inertial, shapes, materials, surfaces, sensors, link flags."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from converters.description import (
    Blob,
    Collision,
    Geometry,
    Inertial,
    InlineSurface,
    Link,
    LinkExtension,
    Material,
    Surface,
    Visual,
)
from converters.errors import PackageNotFoundError, ResourceNotFoundError
from converters.gazebo.blocks import read_surface
from converters.gazebo.materials import gazebo_rgba
from converters.gazebo.tags import to_xml
from converters.sdf.document import SdfContext, line_of, read_pose
from converters.sdf.heightmaps import heightmap_offset, read_heightmap
from converters.sdf.poses import PoseGraph, scoped

# SDF's defaults for a link without <inertial>: 1 kg and a unit inertia (sdformat's Inertial).
DEFAULT_MASS = 1.0
# Link children that only rendering, sensing or other engines use.
LINK_IGNORED = ("kinematic", "must_be_base_link", "enable_wind", "light", "audio_sink")
# Of those, flags whose false value is what twin simulates anyway: false says nothing.
QUIET_WHEN_FALSE = ("kinematic", "must_be_base_link", "enable_wind")


def read_link(
    ctx: SdfContext, graph: PoseGraph, element: Any, prefix: str
) -> tuple[Link, LinkExtension, tuple[InlineSurface, ...]]:
    """One link with its shapes in the link frame, its Gazebo flags and collision surfaces."""
    name = prefix + element.get("name", "")
    X_M_L = graph.pose(name)
    visuals = tuple(_visual(ctx, graph, v, name, prefix, X_M_L) for v in element.findall("visual"))
    collisions, surfaces = [], []
    for index, c in enumerate(element.findall("collision")):
        pose = _part_pose(ctx, graph, c, prefix, X_M_L)
        geometry = _geometry(ctx, c, name)
        if geometry is not None and geometry.shape == "heightmap":
            pose = pose @ heightmap_offset(ctx, c)
        collisions.append(Collision(pose, geometry, c.get("name")))
        if c.find("surface") is not None or c.find("max_contacts") is not None:
            surface, _ = read_surface(c, ctx.values(c))
            surface = _fdir1_in_collision(graph, c, prefix, X_M_L @ pose, surface)
            surfaces.append(InlineSurface(name, index, surface))
    link = Link(name, _inertial(ctx, element, name), visuals, tuple(collisions))
    return link, _extension(ctx, element, name), tuple(surfaces)


def _fdir1_in_collision(
    graph: PoseGraph, collision: Any, prefix: str, X_M_C: np.ndarray, surface: Surface
) -> Surface:
    """`surface` with `fdir1` in the collision frame. gz-physics reads a `gz:expressed_in`
    attribute on `<fdir1>` (gz-sim's mecanum example writes `expressed_in="chassis"`) as the
    frame the direction is written in; without it the direction is the collision's own."""
    element = collision.find("surface/friction/ode/fdir1")
    if surface.fdir1 is None or element is None:
        return surface
    frame = next((v for k, v in element.attrib.items() if _local(k) == "expressed_in"), None)
    if not frame:
        return surface
    X_M_F = graph.pose(scoped(frame.strip(), prefix), element)
    R_C_F = X_M_C[:3, :3].T @ X_M_F[:3, :3]
    return replace(surface, fdir1=tuple(float(v) for v in R_C_F @ np.array(surface.fdir1)))


def _local(key: str) -> str:
    """An attribute's name without its prefix: `gz:expressed_in` and `{uri}expressed_in` (a
    declared prefix) alike."""
    return key.rsplit("}", 1)[-1].rsplit(":", 1)[-1]


def _part_pose(ctx: SdfContext, graph: PoseGraph, element: Any, prefix: str, X_M_L: np.ndarray):
    """A visual's or collision's pose in its link frame (`relative_to` may name another frame)."""
    pose, relative_to = read_pose(ctx, element)
    if relative_to is None:
        return pose
    X_M_F = graph.pose(scoped(relative_to, prefix), element)
    return np.linalg.inv(X_M_L) @ X_M_F @ pose


def _inertial(ctx: SdfContext, link: Any, name: str) -> Inertial:
    element = link.find("inertial")
    if element is None:
        ctx.report.mapped(
            f"link '{name}' <inertial>",
            f"absent: SDF's default {DEFAULT_MASS:g} kg, unit inertia (as Gazebo simulates it)",
        )
        return Inertial(DEFAULT_MASS, np.eye(3))
    pose, _ = read_pose(ctx, element)
    mass = ctx.number(element, "mass", DEFAULT_MASS)
    tensor = np.eye(3)
    moments = element.find("inertia")
    if moments is not None:
        value = {k: ctx.number(moments, k, 0.0) for k in ("ixy", "ixz", "iyz")}
        value |= {k: ctx.number(moments, k, 1.0) for k in ("ixx", "iyy", "izz")}
        tensor = np.array(
            [
                [value["ixx"], value["ixy"], value["ixz"]],
                [value["ixy"], value["iyy"], value["iyz"]],
                [value["ixz"], value["iyz"], value["izz"]],
            ]
        )
    return Inertial(mass, tensor, pose)


def _visual(
    ctx: SdfContext, graph: PoseGraph, element: Any, link: str, prefix: str, X_M_L: np.ndarray
) -> Visual:
    pose = _part_pose(ctx, graph, element, prefix, X_M_L)
    missing = None
    try:
        geometry = _geometry(ctx, element, link)
    except (PackageNotFoundError, ResourceNotFoundError) as exc:  # sdformat never opens it
        geometry, missing = None, str(exc)  # left out and reported, or refused with --strict
    return Visual(pose, geometry, _material(ctx, element), element.get("name"), missing)


def _geometry(ctx: SdfContext, owner: Any, link: str) -> Geometry | None:
    """The one shape inside `<geometry>`; None (reported) when empty or unsupported."""
    geometry = owner.find("geometry")
    shape = (
        None if geometry is None else next((c for c in geometry if isinstance(c.tag, str)), None)
    )
    subject = f"link '{link}' <{owner.tag} name='{owner.get('name', '')}'>"
    if shape is None or shape.tag == "empty":
        return None
    if shape.tag == "heightmap":
        if owner.tag != "collision":  # the collision's height field is drawn
            ctx.report.ignored(subject, "a <heightmap> visual is not drawn; its collision is")
            return None
        return read_heightmap(ctx, shape, subject, directory_of(ctx, shape))
    reader = _SHAPES.get(shape.tag)
    if reader is None:
        ctx.report.ignored(
            subject, f"<{shape.tag}> geometry is not supported; the shape is left out"
        )
        return None
    return reader(ctx, shape, subject)


def _box(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    return Geometry("box", _positive(ctx, shape, ctx.vector(shape, "size", 3, (1.0, 1.0, 1.0))))


def _sphere(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    return Geometry("sphere", _positive(ctx, shape, (ctx.number(shape, "radius", 1.0),)))


def _cylinder(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    size = (ctx.number(shape, "radius", 1.0), ctx.number(shape, "length", 1.0))
    return Geometry(str(shape.tag), _positive(ctx, shape, size))


def _ellipsoid(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    radii = _positive(ctx, shape, ctx.vector(shape, "radii", 3, (1.0, 1.0, 1.0)))
    return Geometry("ellipsoid", radii)


def _plane(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    normal = np.asarray(ctx.vector(shape, "normal", 3, (0.0, 0.0, 1.0)))
    if np.linalg.norm(normal[:2]) > 1e-9 or normal[2] <= 0:
        ctx.report.approximated(subject, f"plane normal {tuple(normal)} drawn as +z")
    return Geometry("plane", ctx.vector(shape, "size", 2, (0.0, 0.0)))


def _mesh(ctx: SdfContext, shape: Any, subject: str) -> Geometry:
    uri = ctx.text(shape, "uri")
    if not uri:
        raise ctx.error(shape, "has no <uri>", "give the mesh file, e.g. model://NAME/meshes/X.stl")
    if shape.find("submesh") is not None:
        ctx.report.ignored(subject, "<submesh> is not supported; the whole mesh is used")
    path = ctx.resolver.resolve(uri, base_dir=directory_of(ctx, shape), element=subject)
    scale = ctx.vector(shape, "scale", 3, (1.0, 1.0, 1.0))
    return Geometry("mesh", (), Path(path), uri, scale)


_SHAPES = {
    "box": _box,
    "sphere": _sphere,
    "cylinder": _cylinder,
    "capsule": _cylinder,
    "ellipsoid": _ellipsoid,
    "plane": _plane,
    "mesh": _mesh,
}


def _positive(ctx: SdfContext, shape: Any, size: tuple[float, ...]) -> tuple[float, ...]:
    if any(v <= 0 for v in size):
        raise ctx.error(shape, f"size {size} has a value ≤ 0", "give positive sizes in metres")
    return size


def _material(ctx: SdfContext, visual: Any) -> Material | None:
    """`<diffuse>` (else `<ambient>`), else the colour of a `Gazebo/<Name>` script material."""
    material = visual.find("material")
    if material is None:
        return None
    name = ctx.text(material, "script/name")
    rgba = None
    for tag in ("diffuse", "ambient"):
        raw = ctx.text(material, tag)
        if raw is not None:
            values = raw.split()
            element = material.find(tag)
            if len(values) not in (3, 4):
                raise ctx.error(element, f"{raw!r} is not a colour", "write r g b [a] in 0-1")
            numbers = [ctx.parse_number(element, v) for v in values] + [1.0]
            r, g, b, a = numbers[:4]  # three or four values, then the default alpha
            rgba = (r, g, b, a)
            break
    if rgba is None and name is not None:
        rgba = gazebo_rgba(name)
    return Material(name, rgba, None)


def _extension(ctx: SdfContext, link: Any, name: str) -> LinkExtension:
    """Link-level Gazebo values: gravity, self_collide, velocity_decay, sensors."""
    for tag in LINK_IGNORED:
        if link.find(tag) is None or (tag in QUIET_WHEN_FALSE and not ctx.flag(link, tag, False)):
            continue
        ctx.report.ignored(f"link '{name}' <{tag}>", "not simulated by twin")
    decay = link.find("velocity_decay")
    damping = None
    if decay is not None:
        damping = max(ctx.number(decay, "linear", 0.0), ctx.number(decay, "angular", 0.0)) or None
    sensors = tuple(
        Blob("sensor", s.get("name"), s.get("type"), to_xml(s), f"{ctx.source}:{line_of(s)}")
        for s in link.findall("sensor")
    )
    gravity = None if link.find("gravity") is None else ctx.flag(link, "gravity", True)
    self_collide = (
        None if link.find("self_collide") is None else ctx.flag(link, "self_collide", False)
    )
    return LinkExtension(
        link=name,
        self_collide=self_collide,
        gravity=gravity,
        damping_factor=damping,
        sensors=sensors,
    )


def directory_of(ctx: SdfContext, element: Any) -> Path:
    """The directory relative URIs start from: the file an `<include>` brought the element from."""
    for ancestor in (element, *element.iterancestors()):
        marked = ancestor.get(INCLUDED_DIR)
        if marked:
            return Path(marked)
    return ctx.base_dir


# Attribute set on a model element spliced in by `<include>`: the directory of its file.
INCLUDED_DIR = "_twin_dir"
