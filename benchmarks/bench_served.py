"""What bounding a world's conversion costs: a served conversion (read in a child forked from the
warm fork server, built again from its read log) against the same conversion in this process.

Run alternately so that both see the same machine load; warm caches (mesh store, collision
cache) on both sides, as a world's second robot finds them. Target: the served conversion costs
at most OVERHEAD_TARGET_S more than the in-process one, or at most RATIO_TARGET times it.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import tomllib

REPO_ROOT = Path(__file__).resolve().parent.parent
CORPUS = REPO_ROOT.parent / "shared" / "corpus"
ROBOTS = ("r2d2_physics", "turtlebot3_burger", "ur5e", "booster_t1")
REPEATS = 5
OVERHEAD_TARGET_S = 0.3  # [s]
RATIO_TARGET = 2.0


def run() -> dict[str, object]:
    """Per robot: median in-process and served conversion [s], their ratio and difference."""
    from converters.isolated import bounded
    from converters.isolated.budget import XacroBudget
    from converters.mjcf.builder import ConvertOptions
    from converters.serving.served import ConversionJob, convert_job, convert_served

    bounded.enable()
    robots = {r["id"]: r for r in tomllib.loads((CORPUS / "robots.toml").read_text())["robot"]}
    results: dict[str, object] = {}
    for robot_id in ROBOTS:
        robot = robots[robot_id]
        path = CORPUS / "packages" / robot["entry"]
        job = ConversionJob(
            str(path),
            path=str(path),
            args=tuple(robot["xacro_args"].items()),
            package_paths=tuple((p, str(CORPUS / "packages" / p)) for p in robot["packages"]),
            options=ConvertOptions(xacro_budget=XacroBudget()),
        )
        convert_served(job, XacroBudget())  # warms caches and the fork server
        here, served = [], []
        for _ in range(REPEATS):
            here.append(_wall(lambda job=job: convert_job(job)))
            served.append(_wall(lambda job=job: convert_served(job, XacroBudget())))
        a, b = statistics.median(here), statistics.median(served)
        results[robot_id] = {
            "in_process_s": round(a, 3),
            "served_s": round(b, 3),
            "ratio": round(b / a, 2),
            "overhead_s": round(b - a, 3),
            "target_met": b - a <= OVERHEAD_TARGET_S or b / a <= RATIO_TARGET,
        }
    return results


def _wall(fn: object) -> float:
    start = time.perf_counter()
    fn()  # type: ignore[operator]
    return time.perf_counter() - start
