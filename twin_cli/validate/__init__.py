"""Validation: the physics checklist that `twin validate` runs on a robot, in-process.

`scenario` reads scenario files (TOML), `checks/` holds one function per check, `runner` builds
the robot under test and runs each check in its own World, `report` renders the results
(terminal, JUnit, JSON, Markdown, plots).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.validate.runner import ValidationRun, validate
    from twin_cli.validate.scenario import Scenario, load_scenario

__all__ = ["Scenario", "ValidationRun", "load_scenario", "validate"]

__getattr__ = lazy_getattr(
    "twin_cli.validate",
    {
        "Scenario": "twin_cli.validate.scenario",
        "load_scenario": "twin_cli.validate.scenario",
        "ValidationRun": "twin_cli.validate.runner",
        "validate": "twin_cli.validate.runner",
    },
)
