"""The SDFormat reader (1.4-1.11): models and worlds → the neutral descriptions.

`document` parses and reads values with file:line errors, `poses` resolves SDFormat's pose
frame semantics (placement frames included), `names` settles pre-1.7 name clashes, `links` and
`joints` read a model's parts, `model` assembles a robot description, `include` brings in
included models (`model://`, scheme-less, Fuel), `world` reads a world. The builder and the
Gazebo stage consume what this produces exactly as they consume a URDF robot.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from converters.description import RobotDescription, WorldDescription
from converters.report import Report
from converters.resources.packages import PackageResolver
from converters.sdf.document import SdfContext, parse_document
from converters.sdf.include import expand_includes
from converters.sdf.model import read_model
from converters.sdf.world import read_world

__all__ = ["read_sdf_model", "read_sdf_world"]


def _context(
    text: str, source: str, base_dir: Path, resolver: PackageResolver | None, report: Report | None
) -> tuple[SdfContext, Any]:
    """The parsed `<sdf>` root and the context its values are read in (its version included)."""
    root = parse_document(text, source)
    resolver = resolver or PackageResolver.create(Path(source) if source else None)
    report = report or Report(source=source)
    return SdfContext(source, base_dir, resolver, report, root.get("version")), root


def read_sdf_model(
    text: str,
    source: str,
    base_dir: Path,
    resolver: PackageResolver | None = None,
    report: Report | None = None,
) -> RobotDescription:
    """The one model of an SDF model file (a world is refused: serve it instead).

    Raises:
        MalformedXMLError, SDFError, PackageNotFoundError, ResourceNotFoundError.
    """
    ctx, root = _context(text, source, base_dir, resolver, report)
    expand_includes(ctx, root)
    models = root.findall("model")
    if root.find("world") is not None:
        raise ctx.error(
            root.find("world"),
            "is a world, not a model",
            "serve it (`twin serve WORLD.sdf`), or convert one of its models",
        )
    if len(models) != 1:
        raise ctx.error(root, f"holds {len(models)} <model> elements", "give exactly one model")
    return read_model(ctx, models[0], text)


def read_sdf_world(
    text: str,
    source: str,
    base_dir: Path,
    resolver: PackageResolver | None = None,
    report: Report | None = None,
) -> WorldDescription:
    """The `<world>` of an SDF world file.

    Raises:
        MalformedXMLError, SDFError, PackageNotFoundError, ResourceNotFoundError.
    """
    ctx, root = _context(text, source, base_dir, resolver, report)
    worlds = root.findall("world")
    if len(worlds) != 1:
        raise ctx.error(
            root, f"holds {len(worlds)} <world> elements", "give one <world> (or spawn a model)"
        )
    return read_world(ctx, worlds[0], text)
