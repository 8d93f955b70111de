"""Spawning's first half: a request's source (a file, a text, an MJCF) loaded into an MjSpec,
converted in process or in a bounded child, with the entity name checked. `attach` puts it
into the world's spec.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco

from twin_cli.errors import InvalidRequestError, SpawnError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import fixed_base, servos

if TYPE_CHECKING:
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import Conversion

MJCF_SUFFIXES = (".xml", ".mjcf")
URDF_SUFFIXES = (".urdf", ".xacro")
SDF_SUFFIXES = (".sdf",)


@dataclass(frozen=True)
class LoadedSource:
    """A spawn source read into a fresh MjSpec that the world may attach.

    Attributes:
        spec: the entity's own spec (a copy; the caller's MjSpec is never modified).
        source: absolute path of the file, or "<MjSpec>".
        report: the converter's report as a dict (URDF/xacro), else None.
        xml: MJCF text of an MjSpec source, for save/load; else None.
        default_name: the robot's own name (model name or file stem).
        description: the URDF text after xacro, for `/robot_description`; None for SDF, MJCF
            and MjSpec sources (ROS tools draw robots from URDF only).
        sensors: the converter's `converters.description.sensors.SensorSpec`s (URDF/SDF).
        notes: what was done to the source that the user should hear (a scene's ground left out).
        cached: the conversion came from the server's cache (`conversion_cache`), unconverted.
        mesh_keys: mesh name → a key equal exactly for equal meshes (`shared_meshes`), or None.
        deferred: convex hulls stand in for collision meshes whose CoACD decomposition was
            left for the background (`decomposing`).
    """

    spec: mujoco.MjSpec
    source: str
    report: dict | None
    xml: str | None
    default_name: str
    description: str | None = None
    sensors: tuple = ()
    notes: tuple[str, ...] = ()
    cached: bool = False
    mesh_keys: dict[str, str] | None = None
    plugins: tuple = ()  # converters.gazebo.drive_records records (URDF/SDF)
    deferred: bool = False


def load_source(request: SpawnRequest, *, defer: bool = False) -> LoadedSource:
    """Reads the request's URDF/xacro/SDF (through the converter), MJCF, text or MjSpec.

    The request's `env` (the caller's package search variables) goes over this process's. In a
    world server a description is read in a bounded child (`convert_bounded`); MJCF is
    MuJoCo's own parser, in this process. With `fixed_base` the converter welds a description's
    root, and `fixed_base.weld_loaded` an MJCF's. With `defer`, in a world server, a description
    file's or text's CoACD meshes that the collision cache lacks get their convex hulls for now
    (`LoadedSource.deferred`; `decomposing` decomposes them in the background).

    Raises:
        SpawnError: the file is missing, of an unknown kind, or not valid MJCF.
        converters.ConversionError: the converter refused the description.
    """
    loaded = _load(request, defer)
    if request.fixed_base and loaded.report is None:
        loaded = fixed_base.weld_loaded(loaded)
    servos.carry_exported_servos(loaded.spec)  # once per load, not per instance of a batch
    return loaded


MUJOCO_DEFAULT_NAME = "MuJoCo Model"  # MjSpec.modelname of a <mujoco> without `model=`


def own_name(spec: mujoco.MjSpec) -> str:
    """The model's own name, "" when MJCF gave none (MuJoCo's default is not the model's)."""
    return "" if spec.modelname == MUJOCO_DEFAULT_NAME else spec.modelname


def _load(request: SpawnRequest, defer: bool) -> LoadedSource:
    if request.read_roots is not None:
        _check_confined(request)
    if request.xml is not None:
        return _load_text(request, defer)
    if isinstance(request.source, mujoco.MjSpec):
        spec = request.source.copy()
        return LoadedSource(spec, "<MjSpec>", None, xml_or_none(spec), own_name(spec) or "model")
    if request.source is None:
        raise SpawnError("model", "<none>", "no source", "give a file or the description text")
    path = Path(request.source).expanduser().resolve()
    if not path.is_file():
        raise SpawnError(path.stem, str(path), "no such file", "check the path")
    lower = path.name.lower()
    if lower.endswith(MJCF_SUFFIXES):
        return _load_mjcf(path)
    if lower.endswith(URDF_SUFFIXES + SDF_SUFFIXES) or _sniff(path) in ("urdf", "sdf"):
        return _load_description(path, request, defer)
    if _sniff(path) == "mjcf":
        return _load_mjcf(path)
    kinds = ", ".join(URDF_SUFFIXES + SDF_SUFFIXES + MJCF_SUFFIXES)
    raise SpawnError(
        path.stem, str(path), "unknown file kind", f"give a URDF, xacro, SDF or MJCF file ({kinds})"
    )


def convert_options(request: SpawnRequest, *, defer: bool = False) -> ConvertOptions:
    """The converter's options that the request sets (`defer`: `CollisionSettings.defer`)."""
    from converters.collision.plan import CollisionSettings
    from converters.isolated.budget import XacroBudget
    from converters.mjcf.builder import ConvertOptions

    limit = request.coacd_cpu_limit
    return ConvertOptions(
        repair_inertia=request.repair_inertia,
        collision=CollisionSettings(defer=defer)
        if limit is None
        else CollisionSettings(cpu_limit=limit, defer=defer),
        strict=request.strict,
        fixed_base=request.fixed_base,
        xacro_budget=XacroBudget.from_env(),  # a served xacro runs bounded, apart from the world
    )


@dataclass(frozen=True)
class Served:
    """How a served conversion runs: `defer` CoACD (`CollisionSettings.defer`), `extra_s` [s]
    of wall time over the served budget (`TWIN_CONVERT_TIMEOUT`), `cancel` to stop it."""

    defer: bool = False
    extra_s: float = 0.0
    cancel: threading.Event | None = None


def convert_bounded(
    request: SpawnRequest,
    *,
    source: str,
    served: Served | None = None,
    **given: str | None,
) -> Conversion:
    """The request's description converted in a bounded child process (`converters.serving.served`):
    whatever the description holds, the world keeps stepping and answering, and a conversion
    over `TWIN_CONVERT_TIMEOUT` / `TWIN_CONVERT_MEMORY` is stopped with what it was doing.

    Args:
        source: the file, or a name for a text.
        served: how it is served (deferred CoACD, extra time, a cancel event); None: as given.
        given: `path=` a file, or `text=` and `base_dir=` a description sent as text.
    """
    from converters.isolated.budget import XacroBudget
    from converters.serving.served import ConversionJob, convert_served

    served = served or Served()
    job = ConversionJob(
        source,
        args=tuple(sorted(request.args.items())),
        package_paths=tuple((k, str(v)) for k, v in sorted(request.package_paths.items())),
        options=convert_options(request, defer=served.defer),
        env=resolving_env(request),
        read_roots=request.read_roots,
        **given,
    )
    budget = XacroBudget.from_env()
    budget = replace(budget, timeout_s=budget.timeout_s + served.extra_s)
    return convert_served(job, budget, served.cancel)


def resolving_env(request: SpawnRequest) -> dict[str, str] | None:
    """The environment to resolve packages in: the caller's variables over this process's
    (unset ones: this process's), or None for this process's own."""
    return None if request.env is None else {**os.environ, **request.env}


def _sniff(path: Path) -> str | None:
    """The format by the root element, for files with an unusual suffix."""
    from converters.formats import format_of

    try:
        with path.open(encoding="utf-8", errors="replace") as handle:
            return format_of(handle.read(4096))
    except OSError:
        return None


def _load_text(request: SpawnRequest, defer: bool) -> LoadedSource:
    """A description sent as text: MJCF is loaded as is, URDF and SDF are converted (`defer`:
    as `_load_description`)."""
    from converters.formats import format_of
    from converters.isolated import bounded
    from twin_cli.world.values import deferred_meshes

    text, label = request.xml or "", request.label
    if format_of(text) == "mjcf":
        try:
            spec = mujoco.MjSpec.from_string(text)
        except ValueError as exc:
            raise SpawnError(label, label, f"not valid MJCF ({exc})", "fix it") from exc
        return LoadedSource(spec, label, None, text, own_name(spec) or "model")
    loaded = convert_text(request, Served(defer=defer and bounded.enabled()))
    return replace(loaded, deferred=bool(deferred_meshes(loaded.report)))


def convert_text(request: SpawnRequest, served: Served | None = None) -> LoadedSource:
    """The request's URDF or SDF text converted in a bounded child (`convert_bounded`)."""
    base_dir = str(request.base_dir) if request.base_dir is not None else None
    done = convert_bounded(
        request, source=request.label, served=served, text=request.xml, base_dir=base_dir
    )
    name = done.report.robot or "model"
    return LoadedSource(
        done.spec,
        request.label,
        done.report.to_dict(),
        xml_or_none(done.spec),
        name,
        _urdf_or_none(done.description.text),
        done.sensors,
        plugins=done.plugins,
    )


def _check_confined(request: SpawnRequest) -> None:
    """A confined request (a DDS peer's) names a file inside its folders, and no MJCF, which
    MuJoCo's own reader would open in this process unwatched.

    Raises:
        OutsideRootsError: the file is elsewhere.
        SpawnError: it is MJCF.
    """
    from converters.errors import OutsideRootsError
    from converters.formats import format_of
    from converters.isolated.confine import inside

    roots = request.read_roots or ()
    if isinstance(request.source, (str, Path)):
        path = Path(request.source)
        if not path.is_absolute() or not inside(path, roots):
            raise OutsideRootsError(str(path), roots)  # as the conversion's own reads are
        if path.name.lower().endswith(MJCF_SUFFIXES) or _sniff(path) == "mjcf":
            raise SpawnError(path.stem, str(path), "is MJCF", CONFINED_FORMATS)
    elif request.xml is not None and format_of(request.xml) == "mjcf":
        raise SpawnError(request.label, request.label, "is MJCF", CONFINED_FORMATS)


CONFINED_FORMATS = "a spawn over DDS takes URDF or SDF, as Gazebo's services do; use `twin spawn`"


def _load_mjcf(path: Path) -> LoadedSource:
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise SpawnError(path.stem, str(path), f"not valid MJCF ({exc})", "fix the file") from exc
    note = strip_scene(spec, path.name)
    notes = (note,) if note else ()
    return LoadedSource(spec, str(path), None, None, own_name(spec) or path.stem, notes=notes)


def strip_scene(spec: mujoco.MjSpec, label: str) -> str | None:
    """Leave out a scene's own ground planes and lights (the world has its own); say so.

    An MJCF with a plane or a light in its worldbody is a scene, such as the `scene.xml` that
    `twin convert` writes: spawned as it is, its plane became a second ground at the spawn
    height. Its robot (every body) is kept.

    Returns:
        The note for the user, or None when `spec` is not a scene.
    """
    planes = [g for g in spec.worldbody.geoms if g.type == mujoco.mjtGeom.mjGEOM_PLANE]
    lights = list(spec.worldbody.lights)
    if not planes and not lights:
        return None
    for element in planes + lights:
        spec.delete(element)
    return (
        f"{label} is a scene ({len(planes)} ground plane(s), {len(lights)} light(s)): spawned "
        "its robot without its ground and lights, since the world has its own"
    )


def _load_description(path: Path, request: SpawnRequest, defer: bool) -> LoadedSource:
    """A converted file, from the conversion cache when no file it read has changed; with
    `defer` in a world server, its CoACD meshes left for the background (`decomposing`)."""
    from converters.isolated import bounded
    from twin_cli.world.conversion_cache import CACHE, cache_key, deferred_keys
    from twin_cli.world.values import deferred_meshes

    key = cache_key(path, request, resolving_env(request))
    defer = defer and bounded.enabled()
    served = Served(defer=defer)
    loaded = CACHE.load(key, lambda: convert_description(path, request, served))
    if not (defer and deferred_meshes(loaded.report)):
        return loaded
    return replace(loaded, deferred=True, mesh_keys=deferred_keys(loaded))


def convert_description(
    path: Path, request: SpawnRequest, served: Served | None = None
) -> LoadedSource:
    """The file converted in a bounded child (`convert_bounded`, as `served` says)."""
    done = convert_bounded(request, source=str(path), served=served, path=str(path))
    spec, report = done.spec, done.report
    servos.carry_exported_servos(spec)  # cached with its servos: a later spawn pays nothing
    name = report.robot or own_name(spec) or path.name.split(".")[0]
    description = _urdf_or_none(done.description.text)
    return LoadedSource(
        spec,
        str(path),
        report.to_dict(),
        None,
        name,
        description,
        done.sensors,
        plugins=done.plugins,
    )


def _urdf_or_none(text: str) -> str | None:
    """The text when it is URDF (what robot_state_publisher and Foxglove draw), else None."""
    from converters.formats import format_of

    return text if text and format_of(text) == "urdf" else None


def xml_or_none(spec: mujoco.MjSpec) -> str | None:
    try:
        return spec.to_xml()
    except (ValueError, RuntimeError):
        return None


def check_entity_name(name: str) -> str:
    """Returns `name` if it can prefix element names ("<name>/...").

    Raises:
        InvalidRequestError: empty, or contains '/' or whitespace.
    """
    from twin_cli.names import EXAMPLE, RULE, name_problem

    problem = name_problem(name)
    if problem is not None:
        raise InvalidRequestError(f"entity name [{name}]", problem, f"use {RULE}, e.g. {EXAMPLE}")
    return name
