"""The world engine: one MuJoCo world (spec, model, data), its entities and its real-time loop.

No I/O but save and load. The server and validation drive it through `World`'s methods; viewers,
recorders and sensors observe it the same way. `engine` holds `World`, a facade over one
`state.WorldState`; the functions that act on the state live in `spawning` (with `spawn`,
`placement`, `posture`), `changes`, `recompile`, `running` (with `loop`, `realtime`,
`observers`, `divergence`), `physics`, `driving` (with `actuation`, `joint_control`),
`engine_threads`, `respec` and `snapshot` (with `savefile`); `entities` and `queries` read
entities; `scene`, `pose` and `values` hold the world's building blocks.
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
