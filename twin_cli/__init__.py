"""twin's runtime: the world engine, its server and client, validation, and the command line.

Packages, by concern (imports point down this list only; `make lint` enforces it):
`cli` (Typer commands, output) → `server` (HTTP API, runtime files, client) and `validate`
(scenarios, checks, reports) → `world` (the engine: spec, model, data, entities, the loop).

Importing this package imports nothing heavy: the public names below load their modules on first
use, so `import twin_cli` (and every client command) stays free of mujoco and numpy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from twin_cli.errors import TwinError
from twin_cli.lazy import lazy_getattr

if TYPE_CHECKING:
    from twin_cli.server.client import Client
    from twin_cli.server.connection import connect
    from twin_cli.validate import Scenario, load_scenario, validate
    from twin_cli.world import (
        GRAVITY_PRESETS,
        EntityInfo,
        JointState,
        Pose,
        SpawnResult,
        Stats,
        World,
        WorldSettings,
    )

__all__ = [
    "GRAVITY_PRESETS",
    "Client",
    "EntityInfo",
    "JointState",
    "Pose",
    "Scenario",
    "SpawnResult",
    "Stats",
    "TwinError",
    "World",
    "WorldSettings",
    "connect",
    "load_scenario",
    "validate",
]

__getattr__ = lazy_getattr(
    "twin_cli",
    {
        **dict.fromkeys(
            (
                "GRAVITY_PRESETS",
                "EntityInfo",
                "JointState",
                "Pose",
                "SpawnResult",
                "Stats",
                "World",
                "WorldSettings",
            ),
            "twin_cli.world",
        ),
        "Client": "twin_cli.server.client",
        "connect": "twin_cli.server.connection",
        "Scenario": "twin_cli.validate.scenario",
        "load_scenario": "twin_cli.validate.scenario",
        "validate": "twin_cli.validate.runner",
    },
)
