"""Validation: the physics checklist that `twin validate` runs on a robot, in-process.

`scenario` reads scenario files (TOML), `checks/` holds one function per check, `robot` builds
the robot under test, `runner` runs each check in its own World (a crash is an ERROR, not a
failure), `report` renders the results (JUnit, JSON, Markdown, plots). `sweep` runs the
checklist on every robot × parameter variant (`variants`) on a process pool or Ray
(`executors`); `sweep_report` renders it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.validate.runner import ValidationRun, validate
    from twin_cli.validate.scenario import Scenario, load_scenario
    from twin_cli.validate.sweep import Axis, SweepRun, VariantRun, parse_axis
    from twin_cli.validate.sweep_errors import SweepError
    from twin_cli.validate.variants import PARAMETERS

__all__ = [
    "PARAMETERS",
    "Axis",
    "Scenario",
    "SweepError",
    "SweepRun",
    "ValidationRun",
    "VariantRun",
    "load_scenario",
    "parse_axis",
    "validate",
]

__getattr__ = lazy_getattr(
    "twin_cli.validate",
    {
        "Scenario": "twin_cli.validate.scenario",
        "load_scenario": "twin_cli.validate.scenario",
        "ValidationRun": "twin_cli.validate.runner",
        "validate": "twin_cli.validate.runner",
        "Axis": "twin_cli.validate.sweep",
        "SweepError": "twin_cli.validate.sweep_errors",
        "SweepRun": "twin_cli.validate.sweep",
        "VariantRun": "twin_cli.validate.sweep",
        "parse_axis": "twin_cli.validate.sweep",
        "PARAMETERS": "twin_cli.validate.variants",
    },
)
