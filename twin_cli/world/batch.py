"""Batch spawning: many instances of one robot in one request, one conversion and one recompile.

A mixin of `twin_cli.world.engine.World` (it uses the world's lock, spec, entities and its
`_attach`, `_rebuild`, `_ground` and `_commit` steps). All or nothing: every name and pose is
checked before anything is attached, and on any later failure every attached instance is removed
from the world spec, so the world is left exactly as it was.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from twin_cli.errors import EntityExistsError, InvalidRequestError
from twin_cli.world import placement, posture, spawn
from twin_cli.world.entities import Entity, index_entities, rest_state, write_state
from twin_cli.world.pose import Pose
from twin_cli.world.values import SpawnResult

MAX_BATCH = 1000  # instances per request: a guard against a runaway script, not a model limit


def batch_names(base: str, count: int) -> list[str]:
    """Gazebo-style instance names `base_0`, `base_1`, … for `count` poses."""
    return [f"{base}_{i}" for i in range(count)]


def check_batch(
    names: Sequence[str], poses: Sequence[Pose], taken: Sequence[str], limit: int = MAX_BATCH
) -> None:
    """Refuses a batch before anything is attached (`limit`: most poses; a world file's models
    have none).

    Raises:
        InvalidRequestError: no poses, counts differ, a name repeats, a pose is not finite.
        EntityExistsError: a name is already an entity of the world.
    """
    if not poses or len(poses) > limit:
        raise InvalidRequestError(
            "batch spawn", f"{len(poses)} poses", f"give 1 to {MAX_BATCH} poses (--at X,Y)"
        )
    if len(names) != len(poses):
        raise InvalidRequestError(
            "batch spawn",
            f"{len(names)} names for {len(poses)} poses",
            "give one name per pose (--names a,b,c) or a base --name",
        )
    seen: set[str] = set()
    for i, (name, pose) in enumerate(zip(names, poses, strict=True)):
        spawn.check_entity_name(name)
        if name in seen:
            raise InvalidRequestError(f"entity name [{name}]", "given twice", "make names unique")
        seen.add(name)
        if name in taken:
            raise EntityExistsError(name)
        values = (pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw)
        if not all(math.isfinite(v) for v in values):
            raise InvalidRequestError(
                f"pose {i} of entity [{name}]", f"{values} is not finite", "give finite numbers"
            )


class BatchSpawning:
    """`spawn_batch` for a World (mixin)."""

    def spawn_batch(
        self,
        source: str | os.PathLike,
        *,
        poses: Sequence[Pose],
        names: Sequence[str] | None = None,
        base: str | None = None,
        args: dict[str, str] | None = None,
        package_paths: dict[str, str] | None = None,
        on_ground: bool = False,
        joints: dict[str, float] | None = None,
        env: dict[str, str] | None = None,
        repair_inertia: bool = False,
    ) -> list[SpawnResult]:
        """Adds one entity per pose, converting the source once and compiling the world once.

        Instances are named `names`, else `base_0`, `base_1`, … (`base` defaults to the robot's
        own name). Each starts as `spawn` would start it (home key, `joints`, `on_ground`).
        Raises what `spawn` raises, plus `check_batch`'s errors; on any error no instance is
        added and the world is unchanged.
        """
        poses = list(poses)
        if names is None and base is not None:
            names = batch_names(spawn.check_entity_name(base), len(poses))
        if names is not None:
            check_batch(list(names), poses, list(self._entities))
        loaded = spawn.load_source(source, args, package_paths, env, repair_inertia)
        if names is None:
            default = "".join(c if c.isalnum() or c in "-_." else "_" for c in loaded.default_name)
            names = batch_names(default or "model", len(poses))
        inputs = {
            "args": dict(args or {}),
            "package_paths": dict(package_paths or {}),
            "env": env,
            "repair_inertia": repair_inertia,
        }
        copies = [replace(loaded, spec=loaded.spec.copy()) for _ in poses]
        return self._spawn_loaded(copies, list(names), poses, on_ground, joints, inputs)

    def spawn_specs(self, items: Sequence[tuple[object, str, Pose]]) -> list[SpawnResult]:
        """Adds one entity per (MjSpec, name, pose) in one compile of the world: a world file's
        models. One spawn each would compile the world once per model, a cost that grows with
        the square of their number (800 boxes: 77 s). All or nothing, as `spawn_batch`."""
        names = [spawn.check_entity_name(name) for _, name, _ in items]
        poses = [pose for _, _, pose in items]
        loaded = [spawn.load_source(spec, None, None) for spec, _, _ in items]  # type: ignore[arg-type]
        return self._spawn_loaded(loaded, names, poses, False, None, {})

    def _spawn_loaded(self, loaded, names, poses, on_ground, joints, inputs):  # noqa: ANN001, ANN202
        """Attaches each loaded source as its name at its pose, compiles once, seeds each."""
        with self.lock:
            check_batch(names, poses, list(self._entities), limit=max(MAX_BATCH, len(poses)))
            try:
                homes = [
                    self._attach(one, n, p) for one, n, p in zip(loaded, names, poses, strict=True)
                ]
                placed, built = self._seed_batch(loaded[0], names, poses, homes, on_ground, joints)
            except BaseException:
                for n in names:
                    spawn.remove_entity(self._spec, n)
                raise
            model, data, index = built
            results = []
            for one, n, (pose, state) in zip(loaded, names, placed, strict=True):
                self._entities[n] = Entity(
                    n, one.source, inputs.get("args", {}), inputs.get("package_paths", {}), pose,
                    on_ground, state, one.report, one.xml, dict(joints or {}), one.description,
                    sensors=one.sensors, plugins=one.plugins, env=inputs.get("env"),
                    repair_inertia=inputs.get("repair_inertia", False),
                )  # fmt: skip
                warnings = [*one.notes, *placement.start_warnings(model, data, index, n, pose.z)]
                results.append(SpawnResult(n, one.source, warnings, one.report, one.cached))
            self._commit(self._spec, model, data, index)
            return results

    def _seed_batch(self, loaded, names, poses, homes, on_ground, joints):  # noqa: ANN001, ANN202
        """One compile of the world with every instance attached; each seeded at rest."""
        kept = [n for n in self._entities if n in self._index]
        model, data, _ = self._rebuild(self._spec, None, loaded.source)
        index = index_entities(model, kept + names)
        starts: list[tuple[Pose, np.ndarray]] = []
        for n, pose, home in zip(names, poses, homes, strict=True):
            ix = index[n]
            targets = posture.joint_targets(model, ix.joints, f"{n}/", joints or {}, n)
            q = posture.apply_targets(spawn.initial_qpos(model, ix, home, pose), ix.qpos, targets)
            if on_ground:  # a fixed base moves its frame: a recompile that keeps joint layouts
                pose, q, (model, data, _) = self._ground(model, data, index, n, pose, q)
                index = index_entities(model, kept + names)
            starts.append((pose, q))
        placed = []
        for n, (pose, q) in zip(names, starts, strict=True):
            state = rest_state(model, index[n], q)
            write_state(data, index[n], state)
            placed.append((pose, state))
        return placed, (model, data, index)
