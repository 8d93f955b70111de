"""Changing a world after its entities were spawned: delete one, move one, replace the lights.

Functions of a world's state (`twin_cli.world.state`); each takes the lock. A change that
recompiles works on a copy of the spec and installs nothing until the compile succeeded, so a
failure leaves the world, the entity's record included, exactly as it was.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from twin_cli.errors import SpawnError
from twin_cli.world import attach, decomposing
from twin_cli.world.entities import EntityIndex
from twin_cli.world.pose import Pose, check_finite, quat_multiply, rotate
from twin_cli.world.queries import root_from_model
from twin_cli.world.recompile import commit, rebuild
from twin_cli.world.respec import count_delete
from twin_cli.world.scene import replace_lights
from twin_cli.world.state import WorldState

if TYPE_CHECKING:
    from converters.description import Light


def delete(state: WorldState, name: str) -> None:
    """Removes entity `name`; the others keep their exact state."""
    with state.lock:
        state.require(name)
        trial = state.spec.copy()
        attach.remove_entity(trial, name)
        entity = state.entities.pop(name)
        try:
            built = rebuild(state, trial, (), entity.source)
        except SpawnError:
            state.entities[name] = entity
            raise
        prefix = f"{name}/"
        state.commands = {k: c for k, c in state.commands.items() if not k.startswith(prefix)}
        state.pushes = [p for p in state.pushes if not p.body.startswith(prefix)]
        state.perturbation = {
            b: w for b, w in state.perturbation.items() if not b.startswith(prefix)
        }
        commit(state, trial, built)
        decomposing.forget(state, name)  # cancelled if no other entity waits for it
        count_delete(state)  # every RENEW_EVERY deletes: a fresh spec (bounded memory)


def set_lights(state: WorldState, lights: Sequence[Light]) -> None:
    """Replace the world's lights (an SDF world's `<light>`s, its included `sun` among them)."""
    with state.lock:
        trial = state.spec.copy()
        replace_lights(trial, lights)
        commit(state, trial, rebuild(state, trial, (), "<lights>"))
        state.lights = list(lights)  # replayed by respec.renew_spec


def set_pose(state: WorldState, name: str, pose: Pose) -> None:
    """Teleports the entity's root to `pose`, at rest (its velocities are zeroed).

    A fixed-base entity is moved by moving its attach frame (a recompile); that also becomes
    its spawn pose.

    Raises:
        InvalidRequestError: a value is not finite. SpawnError: the world does not compile.
    """
    check_finite(pose, f"pose of entity [{name}]")
    with state.lock:
        ix = state.require(name)
        if ix.free_qpos < 0:
            trial = state.spec.copy()
            attach.move_frame(trial, name, pose)
            built = rebuild(state, trial, (), state.entities[name].source)  # may fail
            state.entities[name] = replace(state.entities[name], pose=pose)
            commit(state, trial, built)
            return
        if ix.model_site >= 0 and state.model.site_bodyid[ix.model_site] == 0:
            _move_free_links(state, name, ix, pose)  # unjoined links: all move with the frame
            return
        if ix.model_site >= 0:
            pose = root_from_model(state.model, ix, pose)
        data = state.data
        data.qpos[ix.free_qpos : ix.free_qpos + 3] = pose.position()
        data.qpos[ix.free_qpos + 3 : ix.free_qpos + 7] = pose.quat()
        data.qvel[ix.dofs] = 0.0
        data.qacc_warmstart[ix.dofs] = 0.0


def set_twist(
    state: WorldState,
    name: str,
    linear: tuple[float, float, float],
    angular: tuple[float, float, float],
) -> None:
    """Sets the velocity of a free-floating entity's root: `linear` [m/s] of its origin and
    `angular` [rad/s], both in the world frame (gazebo_ros' SetEntityState). Its joints keep
    their speeds.

    Raises:
        InvalidRequestError: a value is not finite or beyond SPEED, or the entity is fixed.
    """
    from twin_cli.errors import InvalidRequestError
    from twin_cli.physical_ranges import SPEED

    values = (*linear, *angular)
    if not all(math.isfinite(v) and abs(v) <= SPEED for v in values):
        raise InvalidRequestError(
            f"twist of entity [{name}]", f"{values} is not finite or beyond ±{SPEED:g}",
            f"give speeds within ±{SPEED:g} m/s or rad/s",
        )  # fmt: skip
    with state.lock:
        ix = state.require(name)
        if ix.free_qpos < 0 or ix.root < 0:
            raise InvalidRequestError(
                f"twist of entity [{name}]", "it is fixed to the world", "set only its pose"
            )
        model, data = state.model, state.data
        dof = int(model.jnt_dofadr[model.body_jntadr[ix.root]])
        data.qvel[dof : dof + 3] = linear
        local = np.zeros(3)  # a free joint's angular velocity is in the body's frame
        turn = data.qpos[ix.free_qpos + 3 : ix.free_qpos + 7]  # the root's orientation
        mujoco.mju_rotVecQuat(local, np.array(angular), _conjugate(turn))
        data.qvel[dof + 3 : dof + 6] = local


def _conjugate(quat: np.ndarray) -> np.ndarray:
    return np.array([quat[0], -quat[1], -quat[2], -quat[3]])


def _move_free_links(state: WorldState, name: str, ix: EntityIndex, pose: Pose) -> None:
    """Moves every free link of a model of unjoined links rigidly, so that its model frame
    goes from where it is (its spawn or last set pose) to `pose`; at rest."""
    old, qpos = state.entities[name].pose, state.data.qpos
    w, x, y, z = old.quat()
    turn = quat_multiply(pose.quat(), (w, -x, -y, -z))
    for at in attach.free_offsets(state.model, ix):
        a = int(ix.qpos[at])
        offset = (
            float(qpos[a] - old.x),
            float(qpos[a + 1] - old.y),
            float(qpos[a + 2] - old.z),
        )
        qpos[a : a + 3] = np.add(pose.position(), rotate(turn, offset))
        w1, x1, y1, z1 = (float(v) for v in qpos[a + 3 : a + 7])
        qpos[a + 3 : a + 7] = quat_multiply(turn, (w1, x1, y1, z1))
    state.data.qvel[ix.dofs] = 0.0
    state.data.qacc_warmstart[ix.dofs] = 0.0
    state.entities[name] = replace(state.entities[name], pose=pose)
