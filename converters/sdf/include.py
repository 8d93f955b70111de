"""`<include><uri>model://NAME</uri>`: find the model (model.config), splice it in, apply overrides.

Models are found as Gazebo finds them: `model://NAME` on the model roots (`GZ_SIM_RESOURCE_PATH`,
`IGN_GAZEBO_RESOURCE_PATH`, `SDF_PATH`, `GAZEBO_MODEL_PATH`, ROS packages' `gazebo_model_path`
exports) and the directories above the file; a scheme-less `NAME` beside the file, then on the
model roots; both then among the models twin ships (`ground_plane`, `sun`), so a stock Gazebo
world loads without a Gazebo install.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from converters.errors import MalformedXMLError, PackageNotFoundError
from converters.resources.fuel import cached_model, fuel_caches, parse_address
from converters.resources.packages import MODEL_ENVS
from converters.sdf.document import (
    INCLUDED_SOURCE,
    INCLUDED_VERSION,
    SdfContext,
    line_of,
    parse_document,
    source_of,
    version_tuple,
)
from converters.sdf.links import INCLUDED_DIR, directory_of
from converters.sdf.merge import merge_include

SHIPPED_MODELS = Path(__file__).resolve().parent / "models"
# What an <include> may bring in (a Gazebo model directory holds one of these).
INCLUDABLE = ("model", "light", "actor")
# Fuel models twin ships an equivalent of (OpenRobotics' "Ground Plane" and "Sun").
FUEL_SHIPPED = ("ground plane", "sun")
# Includes nested deeper than this are refused: real model trees nest a few levels, and a chain
# of 1,000 model:// includes overflowed the interpreter's stack (RecursionError, an exit 70).
MAX_INCLUDE_DEPTH = 100


def expand_includes(ctx: SdfContext, parent: Any) -> None:
    """Replace every `<include>` under `parent` (and its nested models) by what it names;
    `merge="true"` splices the included model's parts into `parent` instead (`merge`)."""
    for include in parent.findall("include"):
        element = included_element(ctx, include)
        _refuse_circle(ctx, include, parent, element)
        if ctx.flag_attribute(include, "merge"):
            expand_includes(ctx, element)  # its own includes first, as sdformat loads it whole
            merge_include(ctx, parent, include, element)
        else:
            parent.replace(include, element)
    for nested in parent.findall("model"):
        expand_includes(ctx, nested)


def _refuse_circle(ctx: SdfContext, include: Any, parent: Any, element: Any) -> None:
    """Refuse an include of a file that is already being included above it (a → b → a),
    which would otherwise recurse until the interpreter gives up."""
    source = element.get(INCLUDED_SOURCE)
    chain = [a.get(INCLUDED_SOURCE) for a in (parent, *parent.iterancestors())]
    chain = [ctx.source, *reversed([c for c in chain if c])]
    if source in chain:
        circle = " → ".join([*chain[chain.index(source) :], source])
        raise ctx.error(include, f"includes a model that includes it ({circle})", "remove "
                        "the <include> that closes the circle")  # fmt: skip
    if len(chain) > MAX_INCLUDE_DEPTH:
        problem = f"nests includes {len(chain)} levels deep (from {chain[0]})"
        limit = f"twin follows at most {MAX_INCLUDE_DEPTH}; flatten the model tree"
        raise ctx.error(include, problem, limit)


def included_element(ctx: SdfContext, include: Any) -> Any:
    """The `<model>` (or `<light>`) an include names, with its `<name>`, `<pose>`, `<static>`.

    Raises:
        SDFError: no `<uri>`, or the file holds no model; PackageNotFoundError: the model
            was found nowhere (the message lists every place searched).
    """
    uri = ctx.text(include, "uri")
    if not uri:
        raise ctx.error(include, "has no <uri>", "write <uri>model://NAME</uri>")
    path = _model_file(ctx, include, uri)
    try:
        root = parse_document(path.read_text(), str(path))
    except MalformedXMLError as exc:
        raise ctx.error(
            include, f"includes {path}, which is not well-formed XML ({exc})", "include an SDF file"
        ) from exc
    element = next((c for c in root if isinstance(c.tag, str) and c.tag in INCLUDABLE), None)
    if element is None:
        raise ctx.error(include, f"{path} holds no <model> or <light>", "include a model file")
    element.set(INCLUDED_DIR, str(path.parent))
    element.set(INCLUDED_SOURCE, str(path))
    element.set(INCLUDED_VERSION, (root.get("version") or "").strip())
    _override(ctx, include, element)
    return element


def _model_file(ctx: SdfContext, include: Any, uri: str) -> Path:
    if uri.startswith(("https://", "http://")):
        return _fuel_model(ctx, include, uri)
    element = f"{source_of(include, ctx.source)}:{line_of(include)}: <include>"
    base = directory_of(ctx, include)
    try:
        target = ctx.resolver.resolve(uri, base_dir=base, element=element, must_exist=False)
    except PackageNotFoundError:
        shipped = _shipped(uri)
        if shipped is None:
            raise
        target = shipped
    relative = uri.removeprefix("file://")  # libsdformat strips a scheme before its search
    if not target.exists() and "://" not in relative and not Path(relative).is_absolute():
        target = _on_model_roots(ctx, include, relative, target)
    if target.is_dir():
        return _from_config(ctx, include, target)
    if not target.is_file():
        raise ctx.error(include, f"{uri} resolves to {target}, which does not exist", "fix the uri")
    return target


def _on_model_roots(ctx: SdfContext, include: Any, uri: str, beside: Path) -> Path:
    """A scheme-less include URI (`<uri>NAME</uri>`, or a relative `file://NAME`) not beside the
    file: as libsdformat and gz-sim look it up, under each model root
    (`PackageResolver.model_roots`), then among the models twin ships.

    Raises:
        SDFError: found nowhere, with every place tried.
    """
    tried = [beside, *(root / uri for root in ctx.resolver.model_roots())]
    found = next((p for p in tried[1:] if p.exists()), None) or _shipped(f"model://{uri}")
    if found is not None:
        return found
    places = "".join(f"\n  {p}" for p in tried)
    raise ctx.error(
        include,
        f"'{uri}' was found neither beside the file nor on a model path",
        f"put it beside the file, or its parent directory on {', '.join(MODEL_ENVS)}, or export "
        "that directory with <gazebo_ros gazebo_model_path=...> in a package.xml on "
        f"ROS_PACKAGE_PATH or AMENT_PREFIX_PATH; tried:{places}",
    )


def _fuel_model(ctx: SdfContext, include: Any, uri: str) -> Path:
    """A Gazebo Fuel model (`https://fuel.gazebosim.org/1.0/OWNER/models/NAME[/VERSION]`) from
    the local Fuel cache, where `gz fuel download` and Gazebo put it; Gazebo's own ground plane
    and sun fall back to the ones twin ships. twin never downloads."""
    address = parse_address(uri)
    if address is None:
        raise ctx.error(include, f"{uri} is not a Fuel model URI", "write model://NAME")
    if not (address.version or "").isdigit():  # an include's other last segment: the newest
        address = replace(address, version=None)
    cached = cached_model(address, ctx.resolver.env)
    if cached is not None:
        return _from_config(ctx, include, cached)
    name = address.name
    shipped = SHIPPED_MODELS / name.lower().replace(" ", "_")
    if name.lower() in FUEL_SHIPPED and shipped.is_dir():
        return _from_config(ctx, include, shipped)
    raise ctx.error(
        include,
        f"{uri} is a Gazebo Fuel model that is not in the local Fuel cache "
        f"({', '.join(str(c) for c in fuel_caches(ctx.resolver.env))}); twin does not download",
        f"run `gz fuel download -u '{uri}'` where there is internet, or put the model in a "
        "directory on GZ_SIM_RESOURCE_PATH and write model://NAME",
    )


def _shipped(uri: str) -> Path | None:
    if not uri.startswith("model://"):
        return None
    name, _, rest = uri[len("model://") :].partition("/")
    candidate = SHIPPED_MODELS / name / rest
    return candidate if (SHIPPED_MODELS / name).is_dir() else None


def _from_config(ctx: SdfContext, include: Any, directory: Path) -> Path:
    """The SDF file a model directory's model.config names (its newest version), else model.sdf."""
    from lxml import etree

    config = directory / "model.config"
    if config.is_file():
        try:
            with open(config, "rb") as handle:  # Python's open: what confinement watches
                text = handle.read()
            parser = etree.XMLParser(resolve_entities=False, no_network=True)
            files = etree.fromstring(text, parser).findall("sdf")
        except etree.XMLSyntaxError as exc:
            raise ctx.error(include, f"{config} is not valid XML ({exc.msg})", "fix it") from exc
        ranked = sorted(files, key=lambda f: version_tuple(f.get("version") or "0.0"), reverse=True)
        for entry in ranked:
            if entry.text and (directory / entry.text.strip()).is_file():
                return directory / entry.text.strip()
    fallback = directory / "model.sdf"
    if fallback.is_file():
        return fallback
    raise ctx.error(
        include, f"{directory} has no model.config naming an SDF file", "add model.config"
    )


def _override(ctx: SdfContext, include: Any, element: Any) -> None:
    """`<name>`, `<pose>`, `<static>` and `<placement_frame>` written in the include win over
    the model's own."""
    name = ctx.text(include, "name")
    if name:
        element.set("name", name)
    placement = ctx.text(include, "placement_frame")
    if placement:
        if include.find("pose") is None:  # libsdformat refuses it too
            raise ctx.error(
                include,
                f"has <placement_frame>{placement}</placement_frame> but no <pose>",
                "give the <pose> the placement frame is placed at",
            )
        element.set("placement_frame", placement)
    for tag in ("pose", "static"):
        given = include.find(tag)
        if given is None:
            continue
        own = element.find(tag)
        if own is not None:
            element.remove(own)
        element.insert(0, given)
