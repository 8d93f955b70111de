"""World files saved before the model gained elements, loaded into a world that has them.

A joint whose tags offer velocity commands now has a velocity motor: a rotor body with a joint,
an actuator and a tendon (`converters.mjcf.velocity_motors`). A file saved before holds the same
model without them, so its state is shorter by one qpos, one dof, one actuator and one body per
motor, and nothing else moved: the rotors were added after every element of their kind, in the
order each array keeps. Such a state gets the rotors' entries put back in: angle 0, speed that
of the joint each one drives (the motor holds the joint at the rotor's speed), the rest 0.

Later, actuators alone were added (`PUSH`: a Gazebo PID's `cmd_offset` beside its pid plugin,
gz-sim VelocityControl's planar servos): their ctrl entries are put back in as 0 the same way.
"""

from __future__ import annotations

import re
from dataclasses import fields, replace

import mujoco
import numpy as np

from converters.mjcf.export_servos import PID_OFFSET_SUFFIX
from twin_cli.world.entities import EntityIndex, EntityState
from twin_cli.world.snapshot import layout_of
from twin_cli.world.state import STATE
from twin_cli.world.velocity_motors import effort_dofs, is_rotor

_S = mujoco.mjtState
# The state elements whose entries follow the model's qpos, dofs, actuators or bodies (the
# others keep their size: time, activations, equality flags, mocaps, user data, plugins).
_PER = {
    int(_S.mjSTATE_QPOS): "qpos",
    int(_S.mjSTATE_QVEL): "dof",
    int(_S.mjSTATE_WARMSTART): "dof",
    int(_S.mjSTATE_CTRL): "actuator",
    int(_S.mjSTATE_QFRC_APPLIED): "dof",
    int(_S.mjSTATE_XFRC_APPLIED): "body",
}
_ENTITY_PARTS = {
    "qpos": ("qpos", "qpos"),
    "qvel": ("dofs", "dof"),
    "qacc_warmstart": ("dofs", "dof"),
    "qfrc_applied": ("dofs", "dof"),
    "ctrl": ("actuators", "actuator"),
    "xfrc_applied": ("bodies", "body"),
}


def rotor_masks(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    """Per qpos entry, dof, actuator and body of `model`: whether it is a velocity motor's."""
    masks = {
        "qpos": np.zeros(model.nq, bool),
        "dof": np.zeros(model.nv, bool),
        "actuator": np.array([is_rotor(model.actuator(a).name) for a in range(model.nu)], bool),
        "body": np.array([is_rotor(model.body(b).name) for b in range(model.nbody)], bool),
    }
    for j in range(model.njnt):
        if is_rotor(model.joint(j).name):
            masks["qpos"][model.jnt_qposadr[j]] = True
            masks["dof"][model.jnt_dofadr[j]] = True
    return masks


def older_layout(model: mujoco.MjModel, masks: dict[str, np.ndarray]) -> dict[str, int]:
    """The layout `model` had before it had velocity motors."""
    sizes = layout_of(model)
    sizes["nq"] -= int(masks["qpos"].sum())
    sizes["nv"] -= int(masks["dof"].sum())
    sizes["nu"] -= int(masks["actuator"].sum())
    sizes["nbody"] -= int(masks["body"].sum())
    return sizes


def add_rotors(
    model: mujoco.MjModel, layout: dict[str, int], state: np.ndarray
) -> tuple[dict[str, int], np.ndarray]:
    """A world state saved before its joints had velocity motors, with their entries added;
    any other state unchanged."""
    masks = rotor_masks(model)
    if not masks["body"].any() or layout != older_layout(model, masks):
        return layout, state
    if np.size(state) != mujoco.mj_stateSize(model, STATE) - _added(model, masks):
        return layout, state
    new = _widen(model, state, masks, int(model.na))
    _rotor_speeds(model, new[1 + model.nq : 1 + model.nq + model.nv])
    return layout_of(model), new


PUSH = re.compile(rf"({re.escape(PID_OFFSET_SUFFIX)}|^(.*/)?planar:.*VelocityControl:(vx|vy|wz))$")
"""Actuators added after world files were first saved: a Gazebo PID's `cmd_offset` beside its
pid plugin (`JOINT:offset`) and gz-sim VelocityControl's planar servos. Neither adds a joint,
a dof or a body, and the offsets came with the pid plugin's integral activation."""


def push_masks(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    """Per qpos entry, dof, actuator and body of `model`: whether it is a `PUSH` actuator."""
    names = [model.actuator(a).name for a in range(model.nu)]
    return {
        "qpos": np.zeros(model.nq, bool),
        "dof": np.zeros(model.nv, bool),
        "actuator": np.array([PUSH.search(n) is not None for n in names], bool),
        "body": np.zeros(model.nbody, bool),
    }


def add_pushes(
    model: mujoco.MjModel, layout: dict[str, int], state: np.ndarray
) -> tuple[dict[str, int], np.ndarray]:
    """A world state saved before those actuators (`PUSH`), with their ctrl entries added (0:
    they read none, or start from the drive's own hold) and its activations as saved (a pid
    integral the save lacked is added next, `savefile._pid_integrals`); any other unchanged."""
    masks = push_masks(model)
    older = older_layout(model, masks)
    saved_na = int(layout.get("na", -1))
    if not masks["actuator"].any() or {**layout, "na": older["na"]} != older:
        return layout, state
    if not 0 <= saved_na <= model.na:
        return layout, state
    expected = mujoco.mj_stateSize(model, STATE) - _added(model, masks) - (model.na - saved_na)
    if np.size(state) != expected:
        return layout, state
    return {**layout_of(model), "na": saved_na}, _widen(model, state, masks, saved_na)


def _widen(
    model: mujoco.MjModel, state: np.ndarray, masks: dict[str, np.ndarray], na: int
) -> np.ndarray:
    """A saved `state` (with `na` activations) with zeros where `masks` mark new entries."""
    pieces, at = [], 0
    for bit in (1 << k for k in range(int(_S.mjNSTATE))):
        if not int(STATE) & bit:
            continue
        size = na if bit == int(_S.mjSTATE_ACT) else mujoco.mj_stateSize(model, bit)
        kind = _PER.get(bit)
        if kind is None:
            pieces.append(state[at : at + size])
            at += size
            continue
        width = size // len(masks[kind]) if len(masks[kind]) else 0
        old = state[at : at + size - width * int(masks[kind].sum())]
        at += len(old)
        pieces.append(_widened(old, masks[kind], width) if width else old)
    return np.concatenate(pieces)


def add_entity_rotors(model: mujoco.MjModel, index: EntityIndex, saved: EntityState) -> EntityState:
    """An entity's saved spawn state with its velocity motors' entries added, if it is exactly
    the state of the entity without them; any other state unchanged (the restore checks it)."""
    return _entity_widened(rotor_masks(model), index, saved)


def add_entity_pushes(model: mujoco.MjModel, index: EntityIndex, saved: EntityState) -> EntityState:
    """An entity's saved spawn state with the `PUSH` actuators' ctrl added, if it is exactly
    the entity's state without them; any other state unchanged (the restore checks it)."""
    return _entity_widened(push_masks(model), index, saved)


def _entity_widened(
    masks: dict[str, np.ndarray], index: EntityIndex, saved: EntityState
) -> EntityState:
    """`saved` with zeros where `masks` mark new entries, if it is exactly the entity's state
    without them; else unchanged."""
    changes = {}
    for f in fields(EntityState):
        if f.name not in _ENTITY_PARTS:
            continue
        part, kind = _ENTITY_PARTS[f.name]
        mask = masks[kind][getattr(index, part)]
        width = 6 if f.name == "xfrc_applied" else 1
        values = np.asarray(getattr(saved, f.name), float).ravel()
        if values.size != width * int((~mask).sum()):
            return saved  # not this entity's state without the new entries
        if mask.any():
            wide = _widened(values, mask, width)
            changes[f.name] = wide.reshape(-1, 6) if width == 6 else wide
    return replace(saved, **changes) if changes else saved


def _added(model: mujoco.MjModel, masks: dict[str, np.ndarray]) -> int:
    """How many state values the velocity motors add."""
    total = 0
    for bit, kind in _PER.items():
        size = mujoco.mj_stateSize(model, bit)
        total += size // len(masks[kind]) * int(masks[kind].sum()) if len(masks[kind]) else 0
    return total


def _widened(old: np.ndarray, mask: np.ndarray, width: int) -> np.ndarray:
    """`old` (one `width`-wide entry per False of `mask`) with zeros where `mask` is True."""
    keep = np.repeat(~mask, width)
    if old.size != int(keep.sum()):
        raise ValueError(f"{old.size} values for {int(keep.sum())} places")
    out = np.zeros(len(mask) * width)
    out[keep] = old
    return out


def _rotor_speeds(model: mujoco.MjModel, qvel: np.ndarray) -> None:
    """Each rotor at the speed of the joint its motor drives (in place)."""
    joints, rotors = effort_dofs(model)
    qvel[rotors] = qvel[joints]
