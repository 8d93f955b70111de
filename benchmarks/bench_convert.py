"""Conversion time of each corpus robot (xacro → MjSpec → compiled model), and of the humanoid."""

from __future__ import annotations

import time
from pathlib import Path

import tomllib

REPO_ROOT = Path(__file__).resolve().parent.parent
CORPUS = REPO_ROOT.parent / "shared" / "corpus"
REPAIR = {"abb_irb2400_12_155", "anymal_c", "hyq"}
REPEATS = 3


def _time(fn: object) -> float:
    """Best of REPEATS wall times [s] (the first run also warms imports and the CoACD cache)."""
    best = float("inf")
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def run() -> dict[str, object]:
    """Per robot: convert [s] with hull collisions, convert with the default `auto` plan (cached
    CoACD after the first run) [s], compile [s], and mesh triangles carried in the spec."""
    from converters.collision.plan import CollisionSettings
    from converters.mjcf.builder import ConvertOptions
    from converters.pipeline import convert
    from scenarios import HUMANOID

    robots = tomllib.loads((CORPUS / "robots.toml").read_text())["robot"]
    entries = [("humanoid", HUMANOID, {}, [], False)] + [
        (
            r["id"],
            CORPUS / "packages" / r["entry"],
            r["xacro_args"],
            r["packages"],
            r["id"] in REPAIR,
        )
        for r in robots
    ]
    results: dict[str, object] = {}
    for robot_id, path, args, packages, repair in entries:
        paths = {p: CORPUS / "packages" / p for p in packages}

        def go(mode: str, path=path, args=args, paths=paths, repair=repair) -> object:
            options = ConvertOptions(repair_inertia=repair, collision=CollisionSettings(mode=mode))
            return convert(path, args=args, package_paths=paths, options=options)[0]

        spec = go("auto")
        start = time.perf_counter()
        model = spec.compile()
        compile_s = time.perf_counter() - start
        results[robot_id] = {
            "convert_hull_s": round(_time(lambda: go("hull")), 4),
            "convert_auto_cached_s": round(_time(lambda: go("auto")), 4),
            "compile_s": round(compile_s, 4),
            "nbody": model.nbody,
            "ngeom": model.ngeom,
            "mesh_faces": int(model.nmeshface),
        }
    return results
