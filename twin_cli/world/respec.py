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
from collections.abc import Callable, Sequence
from typing import Any

import mujoco
import numpy as np

from twin_cli.world import shared_meshes, spawn
from twin_cli.world.contacts import cap_contact_stiffness
from twin_cli.world.pose import Pose
from twin_cli.world.scene import adopt_world_globals, build_world_spec, replace_lights
from twin_cli.world.sleeping import allow_actuated
from twin_cli.world.values import scene_settings

__all__ = ["RENEW_EVERY", "SpecRenewal", "model_bytes"]

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


class SpecRenewal:
    """World mixin: keeps each entity's prepared spec; every `RENEW_EVERY` deletes, rebuilds.

    Expects `_spec`, `model`, `settings` and `_entities` (World). Called with the lock held.
    """

    _spec: mujoco.MjSpec
    model: mujoco.MjModel
    settings: Any
    _entities: dict
    _reapply_commands: Callable[[mujoco.MjModel, mujoco.MjData], None]
    _lights: Sequence[Any] | None = None  # set_lights' lights, replayed into a renewed spec
    _deletes_since_renewal = 0
    spec_renewals = 0  # accepted renewals, for tests and diagnostics
    spec_renewals_refused = 0  # renewals whose spec did not compile to the running model

    @property
    def _kept_specs(self) -> dict[str, tuple[mujoco.MjSpec, dict[str, str] | None]]:
        return self.__dict__.setdefault("_kept_specs_by_name", {})

    def _keep_spec(self, name: str, child: mujoco.MjSpec, keys: dict[str, str] | None) -> None:
        """Keeps a copy of `child` as prepared for attaching (before shared meshes)."""
        self._kept_specs[name] = (child.copy(), dict(keys) if keys else None)

    def _count_delete(self) -> None:
        for name in [n for n in self._kept_specs if n not in self._entities]:
            del self._kept_specs[name]
        self._deletes_since_renewal += 1
        if self._deletes_since_renewal >= RENEW_EVERY:
            self._deletes_since_renewal = 0
            self.renew_spec()

    def renew_spec(self) -> bool:
        """Rebuilds the world spec from scratch if it compiles to exactly the running model.

        Returns whether the spec was replaced; model, data and entities are never touched.
        """
        fresh = self._fresh_spec()
        if fresh is None or not self._compiles_to_model(fresh):
            self.spec_renewals_refused += 1
            return False
        self._spec = fresh
        self.spec_renewals += 1
        _return_freed_pages()
        return True

    def _compiles_to_model(self, spec: mujoco.MjSpec) -> bool:
        """Whether `spec` compiles, as `World._rebuild` and `_commit` finish every model (joint
        commands written into actuators, contact stiffness capped, actuated robots allowed to
        sleep), to `model` byte for byte."""
        try:
            candidate = spec.compile()
        except (ValueError, RuntimeError):
            return False
        self._reapply_commands(candidate, mujoco.MjData(candidate))
        cap_contact_stiffness(candidate)
        allow_actuated(candidate)
        return model_bytes(candidate) == model_bytes(self.model)

    def _fresh_spec(self) -> mujoco.MjSpec | None:
        """The scene, the world's lights and settings, every entity re-attached in order."""
        if any(n not in self._kept_specs for n in self._entities):
            return None  # an entity spawned before this world kept specs: nothing to rebuild
        fresh = build_world_spec(scene_settings(self.settings))
        if self._lights is not None:
            replace_lights(fresh, self._lights)
        for name in _SETTINGS:
            setattr(fresh, name, getattr(self._spec, name))
        fresh.modelname = self._spec.modelname
        for name in self._entities:
            frame = self._spec.frame(f"{name}/")
            if frame is None:
                return None
            kept, keys = self._kept_specs[name]
            child = kept.copy()
            adopt_world_globals(child, fresh)
            shared_meshes.prepare(child, fresh, keys)
            spawn.attach(fresh, child, name, Pose())
            fresh.frame(f"{name}/").pos = frame.pos  # the frame as it is (on-ground, moves)
            fresh.frame(f"{name}/").quat = frame.quat
        return fresh


def _return_freed_pages() -> None:
    """Asks glibc to give freed heap pages back to the system (no-op elsewhere)."""
    try:
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        return
