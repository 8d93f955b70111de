"""The world spec a World starts from: Gazebo's empty world (ground, sun, SDF physics defaults)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco

from converters.mjcf.world_options import INTEGRATOR, SOLVER, WorldOptions
from converters.mjcf.world_rules import apply_world_physics, world_spec
from twin_cli.world.pose import vec3

if TYPE_CHECKING:
    from converters.description import Light

# The SDF/ODE physics fields MuJoCo has no counterpart for (sdf/1.11/physics.sdf, ode section).
ODE_ONLY_FIELDS = (
    "sor",
    "erp",
    "cfm",
    "precon_iters",
    "min_step_size",
    "contact_max_correcting_vel",
    "contact_surface_layer",
    "max_contacts",
    "friction_model",
    "island_threads",
)


@dataclass(frozen=True)
class SceneSettings:
    """Physics of a world spec: the subset of WorldSettings the compiled model carries.

    Attributes:
        timestep: [s]; gravity: [m/s²]; iterations: solver iterations; solver, integrator: names
        in `converters.mjcf.world_options` SOLVERS / INTEGRATORS; ground: whether to add
        Gazebo's ground plane.
    """

    timestep: float
    gravity: tuple[float, float, float]
    iterations: int
    solver: str = SOLVER
    integrator: str = INTEGRATOR
    ground: bool = True


def build_world_spec(settings: SceneSettings) -> mujoco.MjSpec:
    """An empty world: Gazebo's ground (μ=100, μ2=50) if asked, a sun light, the physics; the
    same spec `twin convert` exports as scene.xml (`converters.mjcf.world_rules.world_spec`)."""
    return world_spec(world_options(settings), ground=settings.ground)


def replace_lights(spec: mujoco.MjSpec, lights: Sequence[Light]) -> None:
    """Replace the world's own lights by `lights` (SDF `<light>`: kind, pose, direction, diffuse).

    SDF kinds map to MuJoCo's: directional, spot, point.
    """
    for light in [light for light in spec.lights if light.parent.name == spec.worldbody.name]:
        spec.delete(light)
    kinds = {
        "directional": mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        "spot": mujoco.mjtLightType.mjLIGHT_SPOT,
        "point": mujoco.mjtLightType.mjLIGHT_POINT,
    }
    for light in lights:
        spec.worldbody.add_light(
            name=light.name,
            type=kinds.get(light.kind, mujoco.mjtLightType.mjLIGHT_POINT),
            pos=[float(v) for v in light.pose[:3, 3]],
            dir=list(light.direction),
            diffuse=list(light.diffuse),
            castshadow=light.cast_shadows,
        )


def world_options(settings: SceneSettings) -> WorldOptions:
    """The MuJoCo options of `settings`."""
    return WorldOptions(
        settings.timestep,
        vec3(settings.gravity),
        settings.iterations,
        settings.solver,
        settings.integrator,
    )


def apply_physics(spec: mujoco.MjSpec, settings: SceneSettings) -> None:
    """Writes the world's options and flags (the ones `twin convert` exports in scene.xml) into
    `spec.option`; MuJoCo's auto-reset is disabled (`world_rules.apply_world_physics`)."""
    apply_world_physics(spec, world_options(settings))


_OPTION_FIELDS = (
    "timestep",
    "gravity",
    "integrator",
    "iterations",
    "solver",
    "cone",
    "jacobian",
    "impratio",
    "tolerance",
    "ls_iterations",
    "ls_tolerance",
    "noslip_iterations",
    "noslip_tolerance",
    "ccd_iterations",
    "ccd_tolerance",
    "density",
    "viscosity",
    "wind",
    "magnetic",
    "o_margin",
    "o_solref",
    "o_solimp",
    "o_friction",
    "disableflags",
    "enableflags",
    "disableactuator",
    "sdf_iterations",
    "sdf_initpoints",
    "sleep_tolerance",
)
_SIZE_FIELDS = ("memory", "nstack", "njmax", "nconmax", "nemax", "nuserdata")
_VISUAL_AUTHORED = (
    "visual_global",
    "visual_headlight",
    "visual_map",
    "visual_quality",
    "visual_rgba",
    "visual_scale",
)


def adopt_world_globals(child: mujoco.MjSpec, world: mujoco.MjSpec) -> None:
    """Gives `child` the world's global settings, so attaching it raises no conflict.

    A robot's own <option>, <size> and <visual> do not apply inside a world (Gazebo ignores a
    model's physics too); copying the world's values avoids MuJoCo's attach-conflict warnings,
    which would otherwise be printed and would, for unauthored world values, take the child's.
    """
    for name in _OPTION_FIELDS:
        setattr(child.option, name, getattr(world.option, name))
    for name in _SIZE_FIELDS:
        setattr(child, name, getattr(world, name))
    for name in _VISUAL_AUTHORED:
        setattr(child.authored, name, 0)
