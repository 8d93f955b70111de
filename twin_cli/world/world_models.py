"""A world file's models converted: as the world loads, and again in full in the background.

As a served world loads (`converters.isolated.bounded` enabled), each model's CoACD meshes that
the collision cache lacks get their convex hulls (`CollisionSettings.defer`), so the world
starts at once; `decomposing` then converts each such model in full with `convert_in_full` and
swaps it in. A world model has no file of its own, so the full conversion reads the world file
again in a bounded child, reads every file the model of that name builds from
(`converters.pipeline.read_build_files`) and sends back its description and read log
(`converters.isolated.replay`); the world's process builds the spec once from them without
opening a file, as any served conversion does, and a cancel kills the child and its CoACD
workers.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import Conversion
    from twin_cli.world.spawn import LoadedSource, Served


@dataclass(frozen=True)
class ModelJob:
    """One world model's full conversion: the world file, its package paths, the model's name
    and the options (picklable: it goes to the child)."""

    path: str
    package_paths: tuple[tuple[str, str], ...]
    name: str
    options: ConvertOptions


def options(*, defer: bool) -> ConvertOptions:
    """How a world model is converted (`defer`: CoACD left for the background).

    One model's non-physical inertia does not refuse a world: Gazebo loads the AWS worlds'
    furniture with such inertias (mostly static, where inertia is never used), and so does
    twin, repaired and said (`sdf_world.file_notes`).
    """
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions

    return ConvertOptions(repair_inertia=True, collision=CollisionSettings(defer=defer))


def build(robot: Any, convert: ConvertOptions) -> Conversion:
    """One model of a world (its terrain as static height fields, as any build) as MjSpec and
    report."""
    from converters.pipeline import build_description

    return build_description(robot, convert)


def loaded(path: str | Path, done: Conversion) -> LoadedSource:
    """A world model as a converted source: its file and model name as the entity's source
    (`twin list`, saves), its sensors and drive plugins, and whether hulls stand in for
    decompositions left for the background (`LoadedSource.deferred`)."""
    from twin_cli.world.spawn import LoadedSource, xml_or_none
    from twin_cli.world.values import deferred_meshes

    name, report = done.description.name, done.report.to_dict()
    return LoadedSource(
        done.spec,
        f"{Path(path).resolve()}#{name}",
        report,
        xml_or_none(done.spec),
        name,
        sensors=done.sensors,
        plugins=done.plugins,
        deferred=bool(deferred_meshes(report)),
    )


def convert_in_full(job: ModelJob, served: Served) -> LoadedSource:
    """`job`'s model converted in full: read in a bounded child (time: the served budget plus
    `served.extra_s`; `served.cancel` kills it), built here once from its read log.

    Raises:
        converters.ConversionError: the world file or the model cannot be read any more.
        converters.errors.ConversionStoppedError: cancelled, or the server is stopping.
    """
    from converters.isolated import bounded, replay
    from converters.isolated.budget import XacroBudget

    budget = XacroBudget.from_env()
    budget = replace(budget, timeout_s=budget.timeout_s + served.extra_s)
    subject = f"{job.path}#{job.name}"
    robot, reads = bounded.run(read_model, job, budget, subject, served.cancel)
    with replay.replaying(reads):
        return loaded(job.path, build(robot, job.options))


def read_model(job: ModelJob) -> tuple[Any, dict]:
    """The child's work: read the world file, then every file the model named builds from, and
    keep the read log; no MjSpec is made here."""
    from converters.errors import InputFileError
    from converters.isolated import replay
    from converters.pipeline import read_build_files
    from converters.report import Report
    from converters.resources.packages import PackageResolver
    from converters.sdf import read_sdf_world
    from twin_cli.files import input_files

    path = Path(job.path)
    with replay.recording() as log:
        resolver = PackageResolver.create(path, dict(job.package_paths) or None)
        text = input_files.read_text(path)
        world = read_sdf_world(text, str(path), path.parent, resolver, Report(source=str(path)))
        robots = [placed.robot for placed in world.models if placed.robot.name == job.name]
        if not robots:
            raise InputFileError(str(path), f"has no model '{job.name}' now", "load it again")
        read_build_files(robots[0], job.options)
    return robots[0], log.entries
