"""The state of one world, declared in one place: what every part of the engine reads and writes.

`World` owns one `WorldState` and hands it to the functions that do the work (spawning,
stepping, physics settings, driving, spec renewal); each takes the state's `lock` itself or
says that its caller holds it. Code outside `twin_cli.world` never sees this object: it uses
`World`'s methods.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from twin_cli.errors import EntityNotFoundError
from twin_cli.world.observers import Observers

if TYPE_CHECKING:
    from converters.description import Light
    from twin_cli.world.actuation import JointCommand, Push
    from twin_cli.world.decomposing import Decomposition
    from twin_cli.world.divergence import Divergence, SpeedBounds
    from twin_cli.world.entities import Entity, EntityIndex
    from twin_cli.world.loop import WorldLock
    from twin_cli.world.native_servos import Law
    from twin_cli.world.values import WorldSettings

WARNINGS_KEPT = 100  # MuJoCo warning texts kept in `mujoco_warnings`
STATE = mujoco.mjtState.mjSTATE_INTEGRATION


@dataclass(eq=False)
class WorldState:
    """One world's spec, compiled model and data, entities and run-time bookkeeping.

    Attributes:
        name, settings: the world's name and physics settings.
        lock: held by the stepping loop for one batch at a time and by every change.
        spec, model, data: the world spec, and the model and data compiled from it.
        entities: entity name → its record, in spawn order.
        index: entity name → where it lives in `model` (renewed at every compile).
        commands: actuator name → the joint command it holds.
        native: actuator name → its own servo law as compiled (`native_servos.capture`).
        pushes: wrenches acting until a world iteration; perturbation: a viewer's drag, by body.
        iterations: steps taken since the last reset; stepping_time: [s] spent in `mj_step`.
        paused: the loop's pause; divergences, divergence_log: entities reset after a NaN or
            a speed far past a joint's limit; speed_bounds: the per-dof bounds of `model`
            (None until the first batch; renewed when the model is a new one).
        mujoco_warnings: MuJoCo's warning texts, the last `WARNINGS_KEPT`.
        scratch_state: a buffer for one `mj_getState` of `model` (a batch's start).
        observers: consumers called between steps (recorder, live stream, sensors).
        threads: engine threads asked for (None: the default); pool_threads: installed.
        lights: an SDF world's lights (replayed into a renewed spec), or None.
        kept_specs: entity name → its spec as prepared for attaching, and its mesh keys.
        deletes_since_renewal, spec_renewals, spec_renewals_refused: spec renewal counters.
        file_notes: what a world file held that twin does not simulate.
        decompositions: entity name → the background decomposition of its collision meshes
            (`decomposing`), pending or finished; absent when it had none.
        page_model: the model it was made for and the plugin-free copy a browser is given
            (`page_model`), or None.
    """

    name: str
    settings: WorldSettings
    lock: WorldLock
    spec: mujoco.MjSpec
    model: mujoco.MjModel
    data: mujoco.MjData
    entities: dict[str, Entity] = field(default_factory=dict)
    index: dict[str, EntityIndex] = field(default_factory=dict)
    commands: dict[str, JointCommand] = field(default_factory=dict)
    native: dict[str, Law] = field(default_factory=dict)
    pushes: list[Push] = field(default_factory=list)
    perturbation: dict[str, tuple[float, ...]] = field(default_factory=dict)
    iterations: int = 0
    stepping_time: float = 0.0
    paused: bool = False
    divergences: int = 0
    divergence_log: list[Divergence] = field(default_factory=list)
    speed_bounds: SpeedBounds | None = None
    mujoco_warnings: deque[str] = field(default_factory=lambda: deque(maxlen=WARNINGS_KEPT))
    scratch_state: np.ndarray = field(default_factory=lambda: np.empty(0))
    observers: Observers = field(default_factory=Observers)
    threads: int | None = None
    pool_threads: int = 0
    lights: list[Light] | None = None
    kept_specs: dict[str, tuple[mujoco.MjSpec, dict[str, str] | None]] = field(default_factory=dict)
    deletes_since_renewal: int = 0
    spec_renewals: int = 0
    spec_renewals_refused: int = 0
    file_notes: tuple[str, ...] = ()
    decompositions: dict[str, Decomposition] = field(default_factory=dict)
    page_model: tuple[mujoco.MjModel, mujoco.MjModel] | None = None

    def __post_init__(self) -> None:
        self.scratch_state = np.empty(mujoco.mj_stateSize(self.model, STATE))

    def require(self, name: str) -> EntityIndex:
        """Where entity `name` lives in the model; the caller holds the lock.

        Raises:
            EntityNotFoundError: no such entity (the message lists the entities).
        """
        if name not in self.entities:
            raise EntityNotFoundError(name, list(self.entities))
        return self.index[name]
