"""The World API's value types and request checks: settings, results, stats, gravity presets."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

from converters.mjcf import world_options as options
from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli.errors import InvalidRequestError
from twin_cli.world.scene import SceneSettings

# Gravity presets [m/s²] (`earth` is the --earth preset 9.81, not empty.world's 9.8).
GRAVITY_PRESETS = {
    "earth": (0.0, 0.0, -9.81),
    "moon": (0.0, 0.0, -1.62),
    "mars": (0.0, 0.0, -3.71),
    "zero": (0.0, 0.0, 0.0),
}


@dataclass(frozen=True)
class WorldSettings:
    """Physics of a new world (SDF defaults: 1 ms step at 1000 Hz, ODE quick 50 iterations).

    Attributes:
        timestep: [s]; rate: real-time update rate [Hz], 0 = as fast as possible;
        gravity: [m/s²]; iterations: solver iterations; ground: Gazebo's ground plane;
        solver, integrator: MuJoCo names (see converters.mjcf.world_options).
    """

    timestep: float = options.TIMESTEP_S
    rate: float = options.UPDATE_RATE_HZ
    gravity: tuple[float, float, float] = options.GRAVITY
    iterations: int = options.ITERATIONS
    ground: bool = True
    solver: str = options.SOLVER
    integrator: str = options.INTEGRATOR
    contact_max_correcting_vel: float = 100.0  # [m/s] ODE's; shown by `twin physics`


@dataclass(frozen=True)
class SpawnResult:
    """What a spawn did: the entity's name and source, start warnings, converter report, and
    whether the conversion came from the server's cache (nothing was converted)."""

    name: str
    source: str
    warnings: list[str]
    report: dict | None
    cached: bool = False


@dataclass(frozen=True)
class EntityInfo:
    """One line of the entity list: name, source file, root position [m], joints (no free)."""

    name: str
    source: str
    position: tuple[float, float, float]
    n_joints: int


@dataclass(frozen=True)
class Stats:
    """`gz stats` figures: factor, sim and real time [s], iterations, paused."""

    factor: float
    sim_time: float
    real_time: float
    iterations: int
    paused: bool


def scene_settings(settings: WorldSettings) -> SceneSettings:
    return SceneSettings(
        settings.timestep,
        settings.gravity,
        settings.iterations,
        settings.solver,
        settings.integrator,
        settings.ground,
    )


def finite_vector(what: str, values: Iterable[float], size: int) -> list[float]:
    try:
        vector = [float(v) for v in values]
    except (TypeError, ValueError) as exc:
        raise InvalidRequestError(
            what, f"{values!r} is not a list of numbers", f"give {size} numbers"
        ) from exc
    if len(vector) != size or not all(math.isfinite(v) for v in vector):
        raise InvalidRequestError(
            what, f"{values!r} is not {size} finite numbers", f"give {size} finite numbers"
        )
    return vector


# [s] smallest step accepted: below it the real-time pacer's steps per second overflow (a
# 5e-324 s step divided by zero; found by the API fuzz), and no robot needs a step under 1 µs.
MIN_TIMESTEP_S = 1e-6


def check_settings(s: WorldSettings) -> None:
    """Raises InvalidRequestError for a setting MuJoCo cannot run with."""
    problems = [
        (
            "timestep",
            s.timestep,
            math.isfinite(s.timestep) and s.timestep >= MIN_TIMESTEP_S,
            f"give a step >= {MIN_TIMESTEP_S:g} s, e.g. 0.001",
        ),
        (
            "rate",
            s.rate,
            math.isfinite(s.rate) and s.rate >= 0,
            "give a rate >= 0 Hz (0 = as fast as possible)",
        ),
        (
            "iterations",
            s.iterations,
            isinstance(s.iterations, int) and s.iterations >= 1,
            "give a whole number >= 1",
        ),
        ("solver", s.solver, s.solver in SOLVERS, f"use one of {', '.join(SOLVERS)}"),
        (
            "integrator",
            s.integrator,
            s.integrator in INTEGRATORS,
            f"use one of {', '.join(INTEGRATORS)}",
        ),
    ]
    for field, value, ok, fix in problems:
        if not ok:
            raise InvalidRequestError(f"physics {field}", f"{value!r} is not valid", fix)
    finite_vector("gravity", s.gravity, 3)
