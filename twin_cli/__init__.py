"""twin's world engine, server, client and command line.

Importing this package imports nothing heavy: the public names below load their modules on first
use, so `import twin_cli` (and every client command) stays free of mujoco and numpy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from twin_cli.errors import TwinError

if TYPE_CHECKING:
    from twin_cli.client import Client, connect
    from twin_cli.scenario import Scenario, load_scenario
    from twin_cli.validate import validate
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

_LAZY = {
    **dict.fromkeys(
        ("GRAVITY_PRESETS", "EntityInfo", "JointState", "Pose", "SpawnResult", "Stats", "World"),
        "twin_cli.world",
    ),
    "WorldSettings": "twin_cli.world",
    "Client": "twin_cli.client",
    "connect": "twin_cli.client",
    "Scenario": "twin_cli.scenario",
    "load_scenario": "twin_cli.scenario",
    "validate": "twin_cli.validate",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'twin_cli' has no attribute {name!r}")
