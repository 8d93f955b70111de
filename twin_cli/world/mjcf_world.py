"""A World built from an MJCF scene (`twin serve scene.xml`), as MuJoCo's `simulate` opens one.

An MJCF that carries its own ground plane or lights is a scene: the `scene.xml` that `twin
convert` writes, or a Menagerie `scene.xml` that includes its robot. Spawned into a world, its
robot is kept and its ground and lights are left out (`spawn.strip_scene`). Served, the scene is
the world: its `<option>` gives the step, gravity, solver, integrator and iterations, the world
gets no Gazebo ground of its own, and the whole scene becomes one entity named after the model.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import SupportsInt

import mujoco

from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli.errors import SpawnError
from twin_cli.world.engine import World
from twin_cli.world.pose import vec3
from twin_cli.world.spawn import MUJOCO_DEFAULT_NAME
from twin_cli.world.values import WorldSettings

MJCF_SUFFIXES = (".xml", ".mjcf")


def is_mjcf_file(path: str | os.PathLike) -> bool:
    """True for a file whose root element is `<mujoco>` (by suffix, then by its first bytes)."""
    path = Path(path)
    if path.suffix.lower() not in MJCF_SUFFIXES or not path.is_file():
        return False
    with path.open("rb") as stream:
        head = stream.read(4096).decode("utf-8", errors="replace")
    return "<mujoco" in head


def world_from_mjcf(path: str | os.PathLike, *, name: str = "default") -> World:
    """A new, stopped world whose physics and contents are the MJCF scene's.

    Raises:
        SpawnError: the file is not valid MJCF, or its model does not compile.
    """
    path = Path(path).resolve()
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise SpawnError(path.stem, str(path), f"not valid MJCF ({exc})", "fix the file") from exc
    option = spec.option
    settings = WorldSettings(
        timestep=float(option.timestep),
        rate=1.0 / float(option.timestep),
        gravity=vec3(option.gravity),
        iterations=int(option.iterations),
        ground=False,
        solver=_named(SOLVERS, option.solver),
        integrator=_named(INTEGRATORS, option.integrator),
    )
    world = World(settings, name=name)
    world.spawn(spec, name=_entity_name(spec.modelname, path))
    return world


def _named(names: Mapping[str, SupportsInt], value: SupportsInt) -> str:
    """twin's name of a MuJoCo enum value (the scene's solver or integrator)."""
    return next(n for n, v in names.items() if int(v) == int(value))


def _entity_name(model: str, path: Path) -> str:
    """The model's name when it has one of its own that follows twin's name rule, else the
    file's stem (MuJoCo names a model without `model=` "MuJoCo Model")."""
    from twin_cli.names import name_problem

    if model and model != MUJOCO_DEFAULT_NAME and name_problem(model) is None:
        return model
    stem = path.name.split(".")[0]
    return stem if name_problem(stem) is None else "scene"
