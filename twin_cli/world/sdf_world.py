"""A World built from an SDF world file, as gzserver starts from `worlds/empty.world`.

The file's `<physics>` and `<gravity>` become the world's settings; each `<model>` (includes
expanded, `model://ground_plane` and `model://sun` shipped with twin) becomes an entity named
after the model at its pose, so `twin list`, `twin pose` and `twin delete` know them; a
`<heightmap>` collision becomes a MuJoCo height field.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from twin_cli.files import input_files
from twin_cli.world import world_models
from twin_cli.world.engine import World
from twin_cli.world.pose import Pose
from twin_cli.world.values import WorldSettings

if TYPE_CHECKING:
    from converters.description.world import PlacedModel
    from converters.report import Report

# Suffixes of Gazebo world files (`twin serve`, `twin load`).
WORLD_SUFFIXES = (".sdf", ".world")


def is_world_file(path: str | os.PathLike) -> bool:
    """True for a Gazebo world file by its suffix; the SDF reader then says what is wrong with
    it, with file:line (a model file given here is refused: it is spawned, not served)."""
    return Path(path).suffix.lower() in WORLD_SUFFIXES


def world_from_sdf(
    path: str | os.PathLike, *, name: str = "default", package_paths: dict[str, str] | None = None
) -> World:
    """A new, stopped world with the file's physics and its models spawned.

    Raises:
        converters.ConversionError: the file or a model in it cannot be read (file:line).
        SpawnError, EntityExistsError: a model cannot be placed.
    """
    from converters.errors import InputFileError
    from converters.report import Report
    from converters.resources.packages import PackageResolver
    from converters.sdf import read_sdf_world

    path = Path(path).resolve()
    resolver = PackageResolver.create(path, package_paths)
    try:
        text = input_files.read_text(path)
    except (OSError, UnicodeDecodeError) as exc:
        problem = "no such file" if isinstance(exc, FileNotFoundError) else f"unreadable ({exc})"
        raise InputFileError(str(path), problem, "give the path of an SDF world file") from exc
    report = Report(source=str(path))
    description = read_sdf_world(text, str(path), path.parent, resolver, report)
    settings = WorldSettings(
        timestep=description.timestep,
        rate=description.rate,
        gravity=description.gravity,
        iterations=description.iterations,
        ground=False,
        contact_max_correcting_vel=description.contact_max_correcting_vel,
    )
    world = World(settings, name=name)
    world.set_lights(description.lights)
    items, notes, redo = _models(path, description.models, package_paths)
    if items:
        world.spawn_specs(items, redo)  # one compile for all of them
    world.file_notes = (*_notes(report, ""), *notes)
    return world


def _models(
    path: Path, models: Sequence[PlacedModel], package_paths: dict[str, str] | None
) -> tuple:
    """Each model converted, as (loaded source, name, pose); the conversion notes; and, for a
    served world (`bounded.enabled`), model name → its full conversion (`world_models`) when
    hulls stand in for its decomposition for now."""
    from converters.isolated import bounded

    items, notes, redo = [], [], {}
    convert = world_models.options(defer=bounded.enabled())
    packages = tuple(sorted((package_paths or {}).items()))
    for placed in models:
        name = placed.robot.name
        done = world_models.build(placed.robot, convert)
        loaded = world_models.loaded(path, done)
        items.append((loaded, name, pose_of(placed.pose)))
        notes += _notes(done.report, f"model '{name}': ")
        if loaded.deferred:
            full = world_models.options(defer=False)
            redo[name] = partial(
                world_models.convert_in_full, world_models.ModelJob(str(path), packages, name, full)
            )
    return items, notes, redo


def _notes(report: Report, prefix: str) -> list[str]:
    """What a conversion left out or could only warn about, one line each (`twin serve` says
    them: a world's populations, actors and unsupported shapes would otherwise vanish)."""
    from converters.report import Outcome

    kept = (Outcome.IGNORED, Outcome.WARNING, Outcome.REPAIRED)
    return [
        f"{e.outcome.value}: {prefix}{e.subject}: {e.detail}"
        for e in report.entries
        if e.outcome in kept
    ]


def load_world(
    path: str | os.PathLike, *, name: str = "default", package_paths: dict[str, str] | None = None
) -> World:
    """A world from a file: a Gazebo SDF world (`.sdf`, `.world`; `package_paths` for its
    `model://` and `package://`), an MJCF scene, or one that `twin save` wrote."""
    from twin_cli.world.mjcf_world import is_mjcf_file, world_from_mjcf

    if is_world_file(path):
        return world_from_sdf(path, name=name, package_paths=package_paths)
    if is_mjcf_file(path):
        return world_from_mjcf(path, name=name)
    from twin_cli.world import savefile

    return savefile.load(path)


def pose_of(T: np.ndarray) -> Pose:
    """A 4×4 model pose as twin's Pose (position and roll-pitch-yaw)."""
    import mujoco

    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.ascontiguousarray(T[:3, :3]).reshape(-1))
    return Pose.at(T[:3, 3], quat)
