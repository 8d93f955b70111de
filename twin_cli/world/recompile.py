"""Recompiling a world after its spec changed: carry every entity's state over, install the result.

A spawn, a delete, a fixed-base move or new lights change the world spec. `rebuild` compiles a
spec into a new model and data that carry every existing entity's exact state (moved by name:
element ids change at every compile) and its joint commands; nothing is installed until
`commit`, so a compile that fails leaves the world as it was. The caller holds the lock.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import mujoco
import numpy as np

from converters.gazebo.friction_pairs import add_friction_pairs
from converters.mjcf.lowest_point import collision_geoms, lowest_point
from twin_cli.errors import SpawnError
from twin_cli.world import actuation, attach, placement
from twin_cli.world.contacts import cap_contact_stiffness
from twin_cli.world.driving import reapply_commands
from twin_cli.world.engine_threads import install_pool
from twin_cli.world.entities import EntityIndex, index_entities, move_states
from twin_cli.world.pose import Pose
from twin_cli.world.sensor_rings import align_sensor_ticks
from twin_cli.world.state import STATE, WorldState

Built = tuple[mujoco.MjModel, mujoco.MjData, dict[str, EntityIndex]]


def rebuild(
    state: WorldState,
    trial: mujoco.MjSpec,
    new: Sequence[str],
    source: str,
    *,
    from_scratch: bool = False,
) -> Built:
    """Compiles `trial` into a new model and data carrying every existing entity's state;
    `new`: the entities being added (indexed too, and named if the compile fails).

    `from_scratch`: `trial` was built anew (`respec.fresh_spec`), not copied from the world's
    spec. MuJoCo's recompile carries state through the ids of the spec's last compile, which a
    new spec never had (it read past the old arrays and crashed); such a spec is compiled on
    its own and every entity's state moved by name, which is all the state a world has.

    Raises:
        SpawnError: the spec does not compile; the world is unchanged.
    """
    add_friction_pairs(trial)  # mu1/mu2 pairs with the world's geoms as they now are
    try:
        if from_scratch:
            model = trial.compile()
            data = mujoco.MjData(model)
        else:
            model, data = trial.recompile(state.model, state.data)
    except (ValueError, RuntimeError) as exc:
        raise SpawnError(
            ", ".join(new) or "world",
            source,
            f"the world does not compile with it ({exc})",
            "fix the model; the world is unchanged",
        ) from exc
    kept = [n for n in state.entities if n in state.index]
    index = index_entities(model, kept + list(new))
    move_states(state.data, state.index, data, index, [n for n in kept if n in index])
    data.time = state.data.time
    reapply_commands(state, model, data, fresh=True)
    return model, data, index


def commit(state: WorldState, spec: mujoco.MjSpec, built: Built) -> None:
    """Installs a rebuilt spec, model and data as the world's, with what every model needs:
    sensor ticks on the clock's grid, the thread pool, contact stiffness the step resolves,
    velocity decay, and the pushes and drags still acting."""
    model, data, index = built
    state.spec, state.model, state.data, state.index = spec, model, data, index
    if model.nsensor:
        align_sensor_ticks(model, data)
    install_pool(state, model, data)
    cap_contact_stiffness(model)
    state.scratch_state = np.empty(mujoco.mj_stateSize(model, STATE))
    pushed = {p.body for p in state.pushes} | set(state.perturbation)
    if pushed:
        actuation.apply_pushes(model, data, state.pushes, pushed, state.perturbation)


def ground(
    state: WorldState, built: Built, name: str, pose: Pose, q: np.ndarray
) -> tuple[Pose, np.ndarray, Built]:
    """Shifts a new entity so its lowest collision point rests on z = 0.

    A floating base moves in its own qpos; a fixed base moves its attach frame, a recompile
    that keeps the joints' layout.
    """
    model, data, index = built
    ix = index[name]
    full = data.qpos.copy()
    full[ix.qpos] = q
    scratch = placement.positioned(model, full)
    low = lowest_point(model, scratch, collision_geoms(model, ix.geoms))
    if low is None:
        return pose, q, built
    pose = replace(pose, z=pose.z - low)
    if ix.free_qpos >= 0:
        q = q.copy()
        for at in attach.free_offsets(model, ix):  # every free link, not only the root
            q[at + 2] -= low
        return pose, q, built
    attach.move_frame(state.spec, name, pose)
    return pose, q, rebuild(state, state.spec, [name], "on-ground placement")
