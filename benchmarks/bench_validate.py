"""Wall time of `twin validate` on the bundled humanoid: whole command, and per check in-process."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

REPEATS = 3


def _cli_seconds() -> tuple[float, int]:
    """Best-of-REPEATS wall time [s] of the full command, and its exit code."""
    import scenarios

    twin = Path(sys.executable).parent / "twin"
    best, code = float("inf"), -1
    for _ in range(REPEATS):
        start = time.perf_counter()
        done = subprocess.run(
            [str(twin), "validate", str(scenarios.HUMANOID), "--json"],
            capture_output=True,
            text=True,
        )
        best = min(best, time.perf_counter() - start)
        code = done.returncode
    return best, code


def run() -> dict:
    """Figures: CLI wall time, conversion time, and each check's own time [s]."""
    import scenarios
    from twin_cli.validate.runner import load_robot, plan, run_check

    cli, code = _cli_seconds()
    start = time.perf_counter()
    robot = load_robot(scenarios.HUMANOID)
    convert_s = time.perf_counter() - start
    checks = {}
    for sc in plan():
        outcome = run_check(robot, sc)
        checks[sc.name] = {"seconds": round(outcome.seconds, 4), "status": outcome.status.value}
    return {
        "twin_validate_humanoid_wall_s": round(cli, 3),
        "exit_code": code,
        "convert_s": round(convert_s, 3),
        "checks_total_s": round(sum(c["seconds"] for c in checks.values()), 3),
        "checks": checks,
    }
