"""Collision-mesh planning: which meshes stay whole, become hulls, or are decomposed (CoACD).

Contract used by the builder (`converters.mjcf.builder`): it gathers every collision mesh of
the robot into `CollisionRequest`s and calls `prepare.prepare_collision_meshes` once, so
decomposition can run in parallel across meshes. Each request gets back a list of convex (or
whole) parts to write as mesh assets, one geom per part. Primitives never reach this module,
so they are never touched.

The `auto` rule (per mesh, first match wins):
1. over 10,000 triangles (Gazebo's "error" size) -> CoACD: the mesh is too heavy to keep;
2. closed mesh whose volume is below 90 % of its convex hull's (`CONVEX_RATIO`) -> CoACD:
   it is concave enough that its hull would fill a cavity (a cup keeps 30-40 %);
3. closed mesh at or above 90 % of its hull -> the hull (capped vertex count);
4. open mesh (volume undefined) over 1,000 triangles (Gazebo's advice) -> CoACD;
5. otherwise (small open mesh) -> the hull.
"""

from __future__ import annotations

import enum
import os
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from converters.errors import CollisionSettingsError

CONVEX_RATIO = 0.90
# Gazebo's guidance for collision meshes: keep under 1,000 triangles; over 10,000 is an error.
TRIANGLES_ADVISED = 1_000
TRIANGLES_MAX = 10_000
# CoACD's relative threshold lives on a mesh scaled so its longest bounding-box edge spans 2
# (coacd Model::Normalize), so a concavity of d metres is 2 d / longest_edge in its units.
COACD_THRESHOLD_RANGE = (0.01, 1.0)


class CollisionMode(enum.Enum):
    """How one collision mesh becomes MuJoCo geoms."""

    AUTO = "auto"
    COACD = "coacd"
    HULL = "hull"
    MESH = "mesh"


@dataclass(frozen=True)
class CoacdParams:
    """`coacd.run_coacd` keyword arguments (names as CoACD spells them) plus twin's hull cap."""

    threshold: float
    max_convex_hull: int
    preprocess_resolution: int
    resolution: int
    mcts_nodes: int
    mcts_iterations: int
    mcts_max_depth: int
    max_ch_vertex: int
    seed: int = 0

    def kwargs(self) -> dict[str, float]:
        return asdict(self)


# Presets trade quality for time. CoACD's own defaults are threshold 0.05, 150 MCTS iterations,
# no part cap. Measured on a 256-triangle cup, one core: fast 2.5 s (16 parts), balanced 6 s.
PRESETS: dict[str, CoacdParams] = {
    "fast": CoacdParams(0.10, 16, 30, 1000, 10, 50, 2, 64),
    "balanced": CoacdParams(0.05, 32, 50, 2000, 20, 100, 3, 128),
    "fine": CoacdParams(0.03, 64, 60, 4000, 20, 150, 3, 256),
}
# CoACD cuts until every part meets `threshold`, then merges down to `max_convex_hull`, so its
# time grows with the parts the threshold asks for (max_convex_hull does not stop the cutting),
# times the MCTS search per cut, times the triangles each cut clips. Above HEAVY_TRIANGLES
# (twice Gazebo's advice) the threshold is raised and the search capped at HEAVY_CAPS; the
# user's explicit knobs still win. Measured, one thread, open_manipulator_x gripper (2,682
# triangles, volume 0.26 of its hull): threshold 0.10 -> 20 s, 0.15 -> 5 s, 0.25 -> 2.3 s.
HEAVY_TRIANGLES = 2_000
HEAVY_CAPS = {
    "threshold": 0.15,
    "max_convex_hull": 12,
    "preprocess_resolution": 30,
    "resolution": 1000,
    "mcts_nodes": 10,
    "mcts_iterations": 50,
    "mcts_max_depth": 2,
}
# Default CPU budget of one mesh's CoACD run [CPU s], counted by the kernel in the worker
# (`converters.collision.worker`), so the same on an idle and a busy machine; a mesh past it
# falls back to its hull, said in the report and never cached. The presets and HEAVY_CAPS bound
# the work itself; this is a safety net kept far above what real meshes take, since CPU time is
# not exact (a mesh right at the budget could go either way). The corpus's costliest mesh,
# open_manipulator_x chain_link1 (21,376 triangles), took 21.2-28.3 CPU s over six runs on a
# shared 2-core virtual machine (the other six meshes 1.5-10 CPU s each, within 7 % run to run).
DEFAULT_CPU_LIMIT = 60.0
# Overrides DEFAULT_CPU_LIMIT for every conversion of a process that does not give its own
# (`twin serve --coacd-cpu-limit` sets it for the world's file and the spawns into it) [CPU s].
CPU_LIMIT_ENV = "TWIN_COACD_CPU_LIMIT"


@dataclass(frozen=True)
class MeshPart:
    """One collision part: vertices [m] (N, 3) float64 in the geom frame, faces (M, 3) int."""

    vertices: np.ndarray
    faces: np.ndarray


@dataclass(frozen=True)
class CollisionRequest:
    """A collision mesh of one link, already scaled into metres.

    `key` is unique per request (e.g. "link/collision_index"); `source` is the mesh file path,
    used in messages and in the cache key together with the scale.
    """

    key: str
    link: str
    source: str
    scale: tuple[float, float, float]
    vertices: np.ndarray
    faces: np.ndarray


def default_cpu_limit() -> float:
    """The CPU budget of one mesh [CPU s]: `$TWIN_COACD_CPU_LIMIT`, else DEFAULT_CPU_LIMIT.

    Raises:
        CollisionSettingsError: the variable is not a positive number.
    """
    text = os.environ.get(CPU_LIMIT_ENV, "").strip()
    if not text:
        return DEFAULT_CPU_LIMIT
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value < float("inf"):
        raise CollisionSettingsError(f"${CPU_LIMIT_ENV}", text, ["a positive number of seconds"])
    return value


@dataclass(frozen=True)
class CollisionSettings:
    """User choices: `mode` is auto|coacd|hull|mesh; `per_link` overrides it for named links.

    `threshold` is CoACD's relative concavity threshold (0.01-1); `threshold_m` gives it in
    metres instead and is converted per mesh (see COACD_THRESHOLD_RANGE). `max_hull_vertices`
    caps every hull and part (default: the preset's). `cpu_limit` is one mesh's CoACD budget
    [CPU s]; past it the mesh falls back to its hull. `wall_limit` [s] is the backstop against
    a hung worker (None: `decompose.WALL_BACKSTOP_FACTOR` times `cpu_limit`, at least
    `decompose.WALL_BACKSTOP_MIN_S`). `defer`: a mesh CoACD would decompose and the cache
    does not hold gets its convex hull now, with `stopped` "deferred" in its report row, and
    is not stored; a later conversion without `defer` decomposes it (a served world does that
    in the background and swaps the result in).
    """

    mode: str = "auto"
    per_link: dict[str, str] = field(default_factory=dict)
    preset: str = "balanced"
    threshold: float | None = None
    max_hulls: int | None = None
    resolution: int | None = None
    seed: int = 0
    jobs: int | None = None
    use_cache: bool = True
    progress: bool = False
    threshold_m: float | None = None
    max_hull_vertices: int | None = None
    cpu_limit: float = field(default_factory=default_cpu_limit)
    wall_limit: float | None = None
    defer: bool = False


@dataclass(frozen=True)
class Decision:
    """The mode chosen for one mesh and why (`convexity` = mesh volume / hull volume)."""

    mode: CollisionMode
    reason: str
    convexity: float | None = None


def parse_mode(value: str, where: str) -> CollisionMode:
    """A mode from its name; `where` names the option for the error message."""
    try:
        return CollisionMode(value)
    except ValueError as exc:
        valid = [m.value for m in CollisionMode]
        raise CollisionSettingsError(where, value, valid) from exc


def check_settings(settings: CollisionSettings) -> None:
    """Raise CollisionSettingsError for an unknown mode or preset, or a contradictory threshold."""
    parse_mode(settings.mode, "--collision")
    for link, mode in settings.per_link.items():
        parse_mode(mode, f"--collision-link {link}=")
    if settings.preset not in PRESETS:
        raise CollisionSettingsError("--coacd-preset", settings.preset, list(PRESETS))
    for option, value in (
        ("--coacd-cpu-limit", settings.cpu_limit),
        ("wall_limit", settings.wall_limit),
    ):
        if value is not None and not 0 < value < float("inf"):
            raise CollisionSettingsError(option, f"{value:g}", ["a positive number of seconds"])
    if settings.threshold is not None and settings.threshold_m is not None:
        raise CollisionSettingsError(
            "--coacd-threshold", "given both relative and in metres", ["one of the two"]
        )


def requested_mode(request: CollisionRequest, settings: CollisionSettings) -> CollisionMode:
    """The mode the user asked for on this mesh's link (per-link override first)."""
    value = settings.per_link.get(request.link, settings.mode)
    return parse_mode(value, f"--collision-link {request.link}=")


def sized_for(params: CoacdParams, n_triangles: int) -> CoacdParams:
    """`params` with its search capped at HEAVY_CAPS when the mesh has over HEAVY_TRIANGLES.

    Caps only make the run cheaper: a coarser threshold (larger), fewer parts, lower
    resolutions and a smaller MCTS search; a preset already below a cap keeps its value.
    """
    if n_triangles <= HEAVY_TRIANGLES:
        return params
    current = params.kwargs()
    capped = {name: min(current[name], cap) for name, cap in HEAVY_CAPS.items()}
    capped["threshold"] = max(params.threshold, HEAVY_CAPS["threshold"])
    return replace(params, **capped)


def coacd_params(request: CollisionRequest, settings: CollisionSettings) -> CoacdParams:
    """The preset, sized for the mesh, with the user's knobs applied (they win over sizing);
    the threshold is converted from metres if given."""
    params = sized_for(PRESETS[settings.preset], len(request.faces))
    updates: dict[str, object] = {"seed": settings.seed}
    if settings.threshold is not None:
        updates["threshold"] = settings.threshold
    if settings.threshold_m is not None:
        extent = np.ptp(np.asarray(request.vertices, float), axis=0).max()
        relative = 2.0 * settings.threshold_m / extent if extent > 0 else 1.0
        updates["threshold"] = float(np.clip(relative, *COACD_THRESHOLD_RANGE))
    if settings.max_hulls is not None:
        updates["max_convex_hull"] = settings.max_hulls
    if settings.resolution is not None:
        updates["resolution"] = settings.resolution
    if settings.max_hull_vertices is not None:
        updates["max_ch_vertex"] = settings.max_hull_vertices
    return replace(params, **updates)


def decide(n_triangles: int, convexity: float | None) -> Decision:
    """The `auto` rule (module docstring) for a mesh of `n_triangles` and given convexity."""
    shape = "open mesh" if convexity is None else f"volume {convexity:.2f} of its hull"
    if n_triangles > TRIANGLES_MAX:
        why = f"{n_triangles} triangles > {TRIANGLES_MAX:,}; {shape}"
        return Decision(CollisionMode.COACD, why, convexity)
    if convexity is not None:
        if convexity < CONVEX_RATIO:
            return Decision(CollisionMode.COACD, f"concave: {shape}", convexity)
        return Decision(CollisionMode.HULL, f"nearly convex: {shape}", convexity)
    if n_triangles > TRIANGLES_ADVISED:
        why = f"open mesh, {n_triangles} triangles > {TRIANGLES_ADVISED:,}"
        return Decision(CollisionMode.COACD, why, None)
    return Decision(CollisionMode.HULL, f"open mesh, {n_triangles} triangles", None)
