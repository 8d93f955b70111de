"""The World API's value types and request checks: settings, results, stats, gravity presets."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import PurePath

from converters.mjcf import world_options as options
from converters.mjcf.world_options import INTEGRATORS, SOLVERS
from twin_cli import physical_ranges as ranges
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
    """One line of the entity list: name, source file, root position [m], joints (no free),
    the collision meshes whose convex hull stands in for their decomposition
    (`hull_stand_ins`), and where the background decomposition of its meshes is
    (`decomposing`: "pending", "done", "failed" (the hulls stay), or None: it had none)."""

    name: str
    source: str
    position: tuple[float, float, float]
    n_joints: int
    hull_stand_ins: tuple[str, ...] = ()
    decomposition: str | None = None


def hull_stand_ins(report: dict | None) -> tuple[str, ...]:
    """`link: mesh file (why)` for each collision mesh of a converter report whose convex hull
    stands in for its CoACD decomposition (over its CPU budget, stopped, or crashed)."""
    rows = (report or {}).get("meshes", [])
    return tuple(
        f"{row['link']}: {PurePath(row['source']).name} ({row['fallback']})"
        for row in rows
        if row.get("fallback")
    )


DEFERRED_STOP = "deferred"  # a report row's `stopped` when CoACD was left for the background


def deferred_meshes(report: dict | None) -> tuple[str, ...]:
    """The keys of a converter report's collision meshes whose decomposition was left for the
    background (`CollisionSettings.defer`)."""
    rows = (report or {}).get("meshes", [])
    return tuple(row["key"] for row in rows if row.get("stopped") == DEFERRED_STOP)


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


def check_settings(s: WorldSettings) -> None:
    """Raises InvalidRequestError for a setting outside its physical range
    (`twin_cli.physical_ranges`: the ranges the API and save files take, so a world's own save
    always loads)."""
    low, high = ranges.TIMESTEP_S
    problems = [
        (
            "timestep",
            s.timestep,
            math.isfinite(s.timestep) and low <= s.timestep <= high,
            f"give a step of {low:g}-{high:g} s, e.g. 0.001",
        ),
        (
            "rate",
            s.rate,
            s.rate == 0
            or (math.isfinite(s.rate) and ranges.MIN_RATE_HZ <= s.rate <= ranges.RATE_HZ),
            f"give 0 (as fast as possible) or {ranges.MIN_RATE_HZ:g}-{ranges.RATE_HZ:g} Hz",
        ),
        (
            "iterations",
            s.iterations,
            isinstance(s.iterations, int) and 1 <= s.iterations <= ranges.ITERATIONS,
            f"give a whole number of 1-{ranges.ITERATIONS}",
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
    gravity = finite_vector("gravity", s.gravity, 3)
    if max(abs(g) for g in gravity) > ranges.GRAVITY_M_S2:
        raise InvalidRequestError(
            "physics gravity",
            f"{s.gravity!r} is beyond ±{ranges.GRAVITY_M_S2:g} m/s² on an axis",
            "give each component within that (Earth's is 9.81)",
        )
