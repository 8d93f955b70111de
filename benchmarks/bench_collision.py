"""Collision meshes: cold vs warm conversion of corpus mesh robots, and the speed-up from --jobs.

Each cold run uses a fresh cache directory; the warm run repeats the conversion against the
cache the cold run filled (no CoACD call: `coacd_runs` is 0). Times include the whole
`converters.convert()` (xacro, URDF, meshes, build, Gazebo tags), not only collision work.
Target (design.md §5): a warm conversion of a 30-link mesh robot under 0.5 s.
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

CORPUS = Path(__file__).resolve().parents[1].parent / "shared" / "corpus" / "packages"
SOLO12 = CORPUS / "example-robot-data/robots/solo_description/robots/solo12.urdf"
ANYMAL = CORPUS / "example-robot-data/robots/anymal_c_simple_description/urdf/anymal.urdf"
WARM_TARGET_S = 0.5


def _convert(path: Path, cache: str, **settings) -> tuple[float, dict]:
    """Convert once with the given collision settings; (wall seconds, collision summary)."""
    from converters import ConvertOptions, convert
    from converters.collision import CollisionSettings

    os.environ["TWIN_CACHE_DIR"] = cache
    packages = {p.name: p for p in CORPUS.iterdir()}
    options = ConvertOptions(repair_inertia=True, collision=CollisionSettings(**settings))
    start = time.perf_counter()
    spec, report = convert(path, package_paths=packages, options=options)
    spec.compile()
    return time.perf_counter() - start, report.summary.get("collision", {})


def _cold_warm(path: Path, **settings) -> dict:
    with tempfile.TemporaryDirectory(prefix="twin-bench-cache-") as cache:
        cold, summary = _convert(path, cache, **settings)
        warm = min(_convert(path, cache, **settings)[0] for _ in range(3))
        _, warm_summary = _convert(path, cache, **settings)
    return {
        "cold_s": round(cold, 3),
        "warm_s": round(warm, 3),
        "cold_over_warm": round(cold / warm, 1),
        "coacd_runs_cold": summary.get("coacd_runs"),
        "coacd_runs_warm": warm_summary.get("coacd_runs"),
        "parts": summary.get("parts"),
        "fallbacks": summary.get("fallbacks"),
    }


def run() -> dict:
    from converters.decompose import default_jobs

    previous = os.environ.get("TWIN_CACHE_DIR")
    cores = default_jobs()
    try:
        fast_1 = _cold_warm(SOLO12, preset="fast", jobs=1)
        fast_n = _cold_warm(SOLO12, preset="fast", jobs=cores)
        balanced = _cold_warm(SOLO12, preset="balanced", jobs=cores)
        anymal = _cold_warm(ANYMAL, preset="fast", jobs=cores)
    finally:
        if previous is None:
            os.environ.pop("TWIN_CACHE_DIR", None)
        else:
            os.environ["TWIN_CACHE_DIR"] = previous
    return {
        "cores": cores,
        "solo12_fast_jobs1": fast_1,
        f"solo12_fast_jobs{cores}": fast_n,
        "jobs_speedup_cold": round(fast_1["cold_s"] / fast_n["cold_s"], 2),
        f"solo12_balanced_jobs{cores}": balanced,
        "anymal_c_78_links_fast": anymal,
        "warm_target_s": WARM_TARGET_S,
        "warm_under_target": max(fast_n["warm_s"], anymal["warm_s"]) < WARM_TARGET_S,
    }
