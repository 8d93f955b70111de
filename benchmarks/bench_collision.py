"""Collision meshes: cold vs warm conversion of every corpus robot with the default settings,
and the speed-up from --jobs on the heaviest mesh robot (open_manipulator_x).

Each cold run uses a fresh cache directory; the warm run repeats the conversion against the
cache the cold run filled (no CoACD call: `coacd_runs` is 0, fallbacks included). Times include
the whole `converters.convert()` (xacro, URDF, meshes, build, Gazebo tags) and the compile.
Targets: a cold default conversion under ~60 s on 2 cores; a warm conversion of a 30-link mesh
robot under 0.5 s.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import tomllib

CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus"
PACKAGES = CORPUS / "packages"
JOBS_ROBOT = "open_manipulator_x"
COLD_TARGET_S = 60.0
WARM_TARGET_S = 0.5


def _robots() -> dict[str, dict]:
    return {r["id"]: r for r in tomllib.loads((CORPUS / "robots.toml").read_text())["robot"]}


def _convert(robot: dict, cache: str, **settings) -> tuple[float, dict]:
    """Convert and compile once with the given collision settings; (wall [s], summary)."""
    from converters import ConvertOptions, convert
    from converters.collision.plan import CollisionSettings

    os.environ["TWIN_CACHE_DIR"] = cache
    packages = {p.name: p for p in PACKAGES.iterdir()}
    options = ConvertOptions(repair_inertia=True, collision=CollisionSettings(**settings))
    start = time.perf_counter()
    spec, report = convert(
        PACKAGES / robot["entry"], args=robot["xacro_args"], package_paths=packages, options=options
    )
    spec.compile()
    return time.perf_counter() - start, report.summary.get("collision", {})


def _cold_warm(robot: dict, **settings) -> dict:
    with tempfile.TemporaryDirectory(prefix="twin-bench-cache-") as cache:
        cold, summary = _convert(robot, cache, **settings)
        warm = min(_convert(robot, cache, **settings)[0] for _ in range(2))
        _, warm_summary = _convert(robot, cache, **settings)
    return {
        "cold_s": round(cold, 2),
        "warm_s": round(warm, 3),
        "collision_warm_s": round(warm_summary.get("seconds", 0.0), 3),
        "coacd_runs_cold": summary.get("coacd_runs", 0),
        "coacd_runs_warm": warm_summary.get("coacd_runs", 0),
        "parts": summary.get("parts", 0),
        "fallbacks": summary.get("fallbacks", 0),
    }


def run() -> dict:
    from converters.collision.decompose import default_jobs

    previous = os.environ.get("TWIN_CACHE_DIR")
    cores = default_jobs()
    robots = _robots()
    try:
        corpus = {rid: _cold_warm(robot) for rid, robot in robots.items()}
        jobs_1 = _cold_warm(robots[JOBS_ROBOT], jobs=1)
        jobs_n = corpus[JOBS_ROBOT]  # default jobs = all cores
    finally:
        if previous is None:
            os.environ.pop("TWIN_CACHE_DIR", None)
        else:
            os.environ["TWIN_CACHE_DIR"] = previous
    slowest = max(corpus, key=lambda rid: corpus[rid]["cold_s"])
    return {
        "cores": cores,
        "corpus_default_settings": corpus,
        f"{JOBS_ROBOT}_jobs1": jobs_1,
        f"{JOBS_ROBOT}_jobs{cores}": jobs_n,
        "jobs_speedup_cold": round(jobs_1["cold_s"] / jobs_n["cold_s"], 2),
        "slowest_cold": [slowest, corpus[slowest]["cold_s"]],
        "cold_under_target": corpus[slowest]["cold_s"] < COLD_TARGET_S,
        # Whole warm conversions over the target; `collision_warm_s` shows how much of it is
        # collision work (the cache) rather than xacro, mesh loading and building.
        "warm_over_target": {
            rid: [row["warm_s"], row["collision_warm_s"]]
            for rid, row in corpus.items()
            if row["warm_s"] >= WARM_TARGET_S
        },
        "warm_never_runs_coacd": all(row["coacd_runs_warm"] == 0 for row in corpus.values()),
    }
