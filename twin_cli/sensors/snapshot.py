"""One copy of a world's state under its lock, and that state's dynamics evaluated outside it.

Sensors must not slow the loop: `take` holds `world.lock` only for
`mj_getState` (time, qpos, qvel, act, controls, applied forces, warm start: a few µs) and the
entity's sensor list; `Evaluator.evaluate` then rebuilds the full forward dynamics of that
instant on scratch data (`mj_forward`, then `mj_rnePostConstraint` for body accelerations and
interaction forces), where the live data after `mj_step` would be one step stale.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import mujoco
import numpy as np

if TYPE_CHECKING:
    from twin_cli.world.engine import World
    from twin_cli.world.entities import Entity

STATE = mujoco.mjtState.mjSTATE_INTEGRATION  # everything mj_step reads, warm start included


@dataclass(frozen=True)
class Snapshot:
    """The state of a world at one sim time (a copy) and what it needs to be evaluated.

    Attributes:
        time: sim time [s]; model: the compiled model the state belongs to.
        state: `mj_getState(STATE)` vector; entity: the observed entity's record (its sensors).
    """

    time: float
    model: mujoco.MjModel
    state: np.ndarray
    entity: Entity


def take(world: World, name: str) -> Snapshot:
    """Copy the world's state and entity `name`'s record, holding the lock once.

    Raises:
        EntityNotFoundError: the world has no entity `name`.
    """
    with world.lock:
        entity = world.entity(name)  # the world's record: read-only here
        model = world.model
        state = np.empty(mujoco.mj_stateSize(model, STATE))
        mujoco.mj_getState(model, world.data, state, STATE)
        return Snapshot(float(world.data.time), model, state, entity)


class Evaluator:
    """Scratch data for one model at a time: the snapshot's positions, velocities and forces."""

    def __init__(self) -> None:
        self.model: mujoco.MjModel | None = None
        self.data: mujoco.MjData | None = None

    def evaluate(self, snapshot: Snapshot, *, dynamics: bool = True) -> mujoco.MjData:
        """MjData at the snapshot's instant: poses only (`dynamics=False`: all rays and cameras
        need), else forward dynamics with cacc, cfrc_int and cfrc_ext."""
        if snapshot.model is not self.model:
            self.model, self.data = snapshot.model, mujoco.MjData(snapshot.model)
        mujoco.mj_setState(self.model, self.data, snapshot.state, STATE)
        if not dynamics:
            mujoco.mj_kinematics(self.model, self.data)
            mujoco.mj_camlight(self.model, self.data)  # cameras' poses: not in mj_kinematics
            return self.data
        mujoco.mj_forward(self.model, self.data)
        mujoco.mj_rnePostConstraint(self.model, self.data)
        return self.data
