"""SDF `<world>` → world description: physics, gravity, lights and the models placed in it."""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description import Light, PlacedModel, WorldDescription
from converters.description.transforms import vec3
from converters.sdf.document import SdfContext, read_pose
from converters.sdf.include import expand_includes
from converters.sdf.model import read_model
from converters.sdf.names import rename_world_clashes
from converters.sdf.world_frames import WorldFrames

# SDF world defaults (sdf/1.11/physics.sdf, world.sdf): 1 ms at 1000 Hz, factor 1, 50 iterations.
DEFAULT_STEP = 0.001
DEFAULT_RATE = 1000.0
DEFAULT_ITERATIONS = 50
DEFAULT_GRAVITY = (0.0, 0.0, -9.8)
# World children that belong to rendering, other engines or ROS; reported, never an error.
WORLD_IGNORED = (
    "scene",
    "gui",
    "atmosphere",
    "wind",
    "magnetic_field",
    "spherical_coordinates",
    "road",
    "population",
    "actor",
    "audio",
    "state",
    "plugin",
)
DEFAULT_MAX_CORRECTING_VEL = (
    100.0  # [m/s] physics.sdf <ode><constraints><contact_max_correcting_vel>
)
CORRECTING_PATH = "ode/constraints/contact_max_correcting_vel"


def read_world(ctx: SdfContext, world: Any, text: str = "") -> WorldDescription:
    """The world's physics and its models (includes expanded), each as a placed description.

    Raises:
        SDFError: bad values, two models with one name, or an unreadable model.
    """
    expand_includes(ctx, world)
    rename_world_clashes(ctx, world)
    physics = _physics(ctx, world)
    models, names = [], set()
    for element in world.findall("model"):
        name = element.get("name", "")
        if name in names:
            raise ctx.error(
                element, f"a second model named '{name}'", "give each model a unique name"
            )
        names.add(name)
    frames = WorldFrames(ctx, world)  # a model may be posed relative_to a frame or model
    for element in world.findall("model"):
        pose = frames.pose(element.get("name", ""))
        models.append(PlacedModel(read_model(ctx, element, text), pose))
    for tag in WORLD_IGNORED:
        if world.find(tag) is not None:
            ctx.report.ignored(f"world <{tag}>", "not simulated by twin")
    return WorldDescription(
        name=world.get("name", "default"),
        source=ctx.source,
        models=tuple(models),
        lights=tuple(_light(ctx, light) for light in world.findall("light")),
        gravity=_gravity(ctx, world),
        **physics,
    )


def _gravity(ctx: SdfContext, world: Any) -> tuple[float, float, float]:
    """`<world><gravity>` (SDF 1.5+), else the first `<physics><gravity>` (where SDF 1.4 has
    it), else SDF's default."""
    if world.find("gravity") is None:
        holder = next((p for p in world.findall("physics") if p.find("gravity") is not None), None)
        if holder is not None:
            return ctx.vector(holder, "gravity", 3, DEFAULT_GRAVITY)
    return ctx.vector(world, "gravity", 3, DEFAULT_GRAVITY)


def _physics(ctx: SdfContext, world: Any) -> dict[str, Any]:
    """The default (first) `<physics>`: step, update rate, target factor, solver iterations."""
    blocks = world.findall("physics")
    chosen = next(
        (p for p in blocks if ctx.flag(p, "default", False)), blocks[0] if blocks else None
    )
    if chosen is None:
        return {
            "timestep": DEFAULT_STEP,
            "rate": DEFAULT_RATE,
            "real_time_factor": 1.0,
            "iterations": DEFAULT_ITERATIONS,
            "contact_max_correcting_vel": DEFAULT_MAX_CORRECTING_VEL,
        }
    step = ctx.number(chosen, "max_step_size", DEFAULT_STEP)
    if step <= 0:
        raise ctx.error(chosen.find("max_step_size"), f"{step} s", "give a positive step in s")
    rate = ctx.number(chosen, "real_time_update_rate", DEFAULT_RATE)
    iterations = ctx.number(chosen, "ode/solver/iters", DEFAULT_ITERATIONS)
    correcting = ctx.number(chosen, CORRECTING_PATH, DEFAULT_MAX_CORRECTING_VEL)
    if correcting < 0:
        raise ctx.error(chosen.find(CORRECTING_PATH), f"{correcting} m/s", "give a speed >= 0")
    if chosen.get("type", "ode") != "ode":
        ctx.report.approximated("world <physics>", f"engine {chosen.get('type')} → MuJoCo")
    return {
        "timestep": step,
        "rate": max(rate, 0.0),
        "real_time_factor": ctx.number(chosen, "real_time_factor", 1.0),
        "iterations": max(int(iterations), 1),
        "contact_max_correcting_vel": correcting,
    }


def _light(ctx: SdfContext, light: Any) -> Light:
    pose, _ = read_pose(ctx, light)
    direction = np.asarray(ctx.vector(light, "direction", 3, (0.0, 0.0, -1.0)))
    diffuse = ctx.text(light, "diffuse") or "0.8 0.8 0.8 1"
    colour = vec3(float(v) for v in diffuse.split()[:3])
    return Light(
        name=light.get("name", "light"),
        kind=light.get("type", "point"),
        pose=pose,
        direction=vec3(pose[:3, :3] @ direction),
        diffuse=colour,
        cast_shadows=ctx.flag(light, "cast_shadows", False),
    )
