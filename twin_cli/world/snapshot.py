"""A world's state as a plain value: what `twin save` writes and `twin load` restores.

`take` copies it under the world's lock; `restore` writes one back into a world that holds the
same entities. The save file is only its JSON form, so the file
format never reaches into the world's internals.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numpy as np

from twin_cli.errors import InvalidRequestError
from twin_cli.world.actuation import JointCommand, Push
from twin_cli.world.driving import reapply_commands, release_commands
from twin_cli.world.entities import Entity, typed_like
from twin_cli.world.state import STATE, WorldState
from twin_cli.world.values import WorldSettings

LAYOUT_FIELDS = ("nq", "nv", "na", "nu", "nbody", "neq", "nmocap")


@dataclass(frozen=True)
class WorldSnapshot:
    """Everything that decides how a world goes on: settings, entities, commands and state.

    Attributes:
        name: the world's name.
        settings: its physics settings.
        paused, iterations, divergences: the run's flags and counters.
        entities: every entity's record (request, spawn pose and spawn state), in spawn order.
        commands: the joint commands held; pushes: the pushes still acting.
        layout: the compiled model's sizes (`LAYOUT_FIELDS`), to check a restore against.
        state: `mj_getState(mjSTATE_INTEGRATION)` of the whole world.
    """

    name: str
    settings: WorldSettings
    paused: bool
    iterations: int
    divergences: int
    entities: tuple[Entity, ...]
    commands: tuple[JointCommand, ...]
    pushes: tuple[Push, ...]
    layout: dict[str, int]
    state: np.ndarray


def layout_of(model: mujoco.MjModel) -> dict[str, int]:
    """The model's sizes that a state vector's layout depends on."""
    return {k: int(getattr(model, k)) for k in LAYOUT_FIELDS}


def state_of(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The world's full integration state."""
    state = np.empty(mujoco.mj_stateSize(model, STATE))
    mujoco.mj_getState(model, data, state, STATE)
    return state


def take(state: WorldState) -> WorldSnapshot:
    """The world's settings, entities, commands and full state, copied under the lock."""
    with state.lock:
        return WorldSnapshot(
            state.name,
            state.settings,
            state.paused,
            state.iterations,
            state.divergences,
            tuple(state.entities.values()),
            tuple(state.commands.values()),
            tuple(state.pushes),
            layout_of(state.model),
            state_of(state.model, state.data),
        )


def restore(state: WorldState, snapshot: WorldSnapshot) -> None:
    """Writes a snapshot's state, counters, commands and spawn states into the world.

    The world must hold the snapshot's entities, compiled to the same layout (a world rebuilt by
    spawning the same requests in the same order).

    Raises:
        InvalidRequestError: other entities, or another layout; the world is unchanged.
    """
    with state.lock:
        names = [e.name for e in snapshot.entities]
        size = mujoco.mj_stateSize(state.model, STATE)
        if (
            names != list(state.entities)
            or snapshot.layout != layout_of(state.model)
            or np.size(snapshot.state) != size
        ):
            raise InvalidRequestError(
                "world snapshot",
                f"entities {names} in layout {snapshot.layout} with {np.size(snapshot.state)} "
                f"state values, this world has {list(state.entities)} in "
                f"{layout_of(state.model)} with {size}",
                "restore into a world that spawned the same sources in the same order",
            )
        records = {  # all checked before any is replaced: a bad one changes nothing
            e.name: _restored(state.entities[e.name], e) for e in snapshot.entities
        }
        state.entities.update(records)
        mujoco.mj_setState(state.model, state.data, np.asarray(snapshot.state, float), STATE)
        state.iterations, state.divergences = snapshot.iterations, snapshot.divergences
        state.paused = snapshot.paused
        kept = {c.actuator for c in snapshot.commands}
        dropped = [c for key, c in state.commands.items() if key not in kept]
        state.commands = {c.actuator: c for c in snapshot.commands}
        release_commands(state, state.model, state.data, dropped)
        reapply_commands(state, state.model, state.data, fresh=False)
        state.pushes = list(snapshot.pushes)


def _restored(now: Entity, saved: Entity) -> Entity:
    """The record a restore leaves: what the snapshot owns (source, request, pose, spawn state)
    on the world's own record of what it compiled (report, MJCF, description, sensors,
    plugins). A decomposition swapped in after the snapshot was taken (a `twin load` whose
    background CoACD lands before the saved state is written) keeps its report and MJCF."""
    return replace(
        now,
        source=saved.source,
        request=saved.request,
        pose=saved.pose,
        spawn_state=typed_like(now.spawn_state, saved.spawn_state),
    )
