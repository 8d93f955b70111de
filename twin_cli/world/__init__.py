"""The world engine: one MuJoCo world (spec, model, data), its entities and its real-time loop.

No I/O but save and load. The server and validation drive it through `World`'s methods; viewers,
recorders and sensors observe it the same way. Modules: `engine` (the World), `spawn`,
`placement`, `posture` (adding entities), `entities`, `queries` (reading them), `running`,
`loop`, `realtime` (stepping, pacing, the real-time factor), `physics`, `driving`, `actuation`
(settings, pushes, joint commands), `divergence`, `scene`, `savefile`, `pose`, `values`.
"""

from __future__ import annotations

from twin_cli.world.engine import World
from twin_cli.world.pose import Pose
from twin_cli.world.queries import JointState
from twin_cli.world.values import GRAVITY_PRESETS, EntityInfo, SpawnResult, Stats, WorldSettings

__all__ = [
    "GRAVITY_PRESETS",
    "EntityInfo",
    "JointState",
    "Pose",
    "SpawnResult",
    "Stats",
    "World",
    "WorldSettings",
]
