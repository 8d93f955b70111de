"""Renewing the world spec from scratch, so that spawn/delete cycles keep memory bounded.

MuJoCo 4.0.0 keeps memory in an MjSpec for every entity attached and later deleted, even with
every element of it deleted: measured, a world spawning and deleting a one-link URDF box keeps
0.07 MiB a cycle for good (0.22 MiB of resident memory a cycle before glibc returns freed
pages), so the soak benchmark grew 88 → 446 MiB in 3 minutes. `MjSpec.copy()` carries that
memory along, and so does attaching the old spec into a new one; only dropping the spec
releases it. An MJCF round trip would, but `to_xml` writes 6 significant digits.

So the world keeps each entity's spec as prepared for attaching, and every `RENEW_EVERY`
deletes it builds a new spec the way it built the old one: the scene from the settings, the
SDF world's lights, the physics options of the running spec, and every entity re-attached in
order in its frame as the frame is now. The result is compiled and compared byte for byte
(`mj_saveModel`) with the running model; only an identical model is accepted, and then only the
spec is swapped: model, data, entities, commands and pushes stay the very objects they were, so
the world steps exactly as before. A spec that differs (a shared mesh that now comes in another
order) is dropped and counted in `spec_renewals_refused`; the next renewal tries again.
After a renewal glibc is asked to return freed pages (`malloc_trim`), so resident memory shows
what is held.
"""

from __future__ import annotations

import ctypes

import mujoco
import numpy as np

from converters.gazebo.friction_pairs import add_friction_pairs
from twin_cli.world import attach, shared_meshes
from twin_cli.world.contacts import cap_contact_stiffness
from twin_cli.world.driving import reapply_commands
from twin_cli.world.pose import Pose
from twin_cli.world.scene import adopt_world_globals, build_world_spec, replace_lights
from twin_cli.world.sleeping import allow_actuated
from twin_cli.world.state import WorldState
from twin_cli.world.values import scene_settings

__all__ = ["RENEW_EVERY", "count_delete", "fresh_spec", "keep_spec", "model_bytes", "renew_spec"]

# Deletes between renewals. A renewal costs one compile of the world (a few ms for small
# worlds); the memory it bounds is ~0.04-0.08 MiB a cycle, so at most ~2 MiB stays held.
RENEW_EVERY = 20


def model_bytes(model: mujoco.MjModel) -> bytes:
    """The model as MuJoCo's binary MJB file: every array, option and name, exactly."""
    buffer = np.empty(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


# MjSpec settings that physics changes (gravity, step, solver, sleep) write into the world spec.
_SETTINGS = ("option", "visual", "stat", "compiler", "memory", "nstack", "njmax", "nconmax")


def keep_spec(
    state: WorldState, name: str, child: mujoco.MjSpec, keys: dict[str, str] | None
) -> None:
    """Keeps a copy of `child` as prepared for attaching (before shared meshes)."""
    state.kept_specs[name] = (child.copy(), dict(keys) if keys else None)


def count_delete(state: WorldState) -> None:
    """Forgets deleted entities' specs; every `RENEW_EVERY` deletes, renews the spec."""
    for name in [n for n in state.kept_specs if n not in state.entities]:
        del state.kept_specs[name]
    state.deletes_since_renewal += 1
    if state.deletes_since_renewal >= RENEW_EVERY:
        state.deletes_since_renewal = 0
        renew_spec(state)


def renew_spec(state: WorldState) -> bool:
    """Rebuilds the world spec from scratch if it compiles to exactly the running model.

    Returns whether the spec was replaced; model, data and entities are never touched. The
    caller holds the lock.
    """
    fresh = fresh_spec(state)
    if fresh is not None:
        add_friction_pairs(fresh)
    if fresh is None or not _compiles_to_model(state, fresh):
        state.spec_renewals_refused += 1
        return False
    state.spec = fresh
    state.spec_renewals += 1
    _return_freed_pages()
    return True


def _compiles_to_model(state: WorldState, spec: mujoco.MjSpec) -> bool:
    """Whether `spec` compiles, as `recompile.rebuild` and `commit` finish every model (joint
    commands written into actuators, contact stiffness capped, actuated robots allowed to
    sleep), to the running model byte for byte."""
    try:
        candidate = spec.compile()
    except (ValueError, RuntimeError):
        return False
    data = mujoco.MjData(candidate)
    if candidate.na == state.model.na:
        data.act[:] = state.data.act  # position servos size their ramps from their reference
    reapply_commands(state, candidate, data, fresh=True)
    if candidate.nu == state.model.nu:  # a ramp's range is where it started: command state
        candidate.actuator_actrange[:] = state.model.actuator_actrange
    cap_contact_stiffness(candidate)
    allow_actuated(candidate)
    return model_bytes(candidate) == model_bytes(state.model)


Kept = tuple[mujoco.MjSpec, dict[str, str] | None]  # a spec as prepared, and its mesh keys


def fresh_spec(state: WorldState, replaced: dict[str, Kept] | None = None) -> mujoco.MjSpec | None:
    """The scene, the world's lights and settings, every entity re-attached in order, each
    from its kept spec or from the one `replaced` gives for it (prepared as `keep_spec` keeps
    them); None when an entity has no kept spec or no frame."""
    replaced = replaced or {}
    if any(n not in state.kept_specs for n in state.entities):
        return None  # an entity spawned before this world kept specs: nothing to rebuild
    fresh = build_world_spec(scene_settings(state.settings))
    if state.lights is not None:
        replace_lights(fresh, state.lights)
    for name in _SETTINGS:
        setattr(fresh, name, getattr(state.spec, name))
    fresh.modelname = state.spec.modelname
    for name in state.entities:
        frame = state.spec.frame(f"{name}/")
        if frame is None:
            return None
        kept, keys = replaced.get(name) or state.kept_specs[name]
        child = kept.copy()
        adopt_world_globals(child, fresh)
        shared_meshes.prepare(child, fresh, keys)
        attach.attach(fresh, child, name, Pose())
        fresh.frame(f"{name}/").pos = frame.pos  # the frame as it is (on-ground, moves)
        fresh.frame(f"{name}/").quat = frame.quat
    return fresh


def _return_freed_pages() -> None:
    """Asks glibc to give freed heap pages back to the system (no-op elsewhere)."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        return
