"""Spawning entities into a world: one request, one or many instances, one compile, all or none.

A single spawn is a batch of one. Every name and pose is checked before anything is attached;
on any later failure every attached instance is removed from the world spec, so the world is
left exactly as it was. The source is read (and converted) before the lock is taken, so a slow
conversion does not stall the stepping loop.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from twin_cli.errors import EntityExistsError, InvalidRequestError, SpawnError
from twin_cli.spawn_request import SpawnRequest, as_request
from twin_cli.world import attach, placement, posture, shared_meshes, spawn
from twin_cli.world.entities import Entity, EntityState, index_entities, rest_state, write_state
from twin_cli.world.plugin_holds import hold_from_load
from twin_cli.world.pose import Pose, check_finite
from twin_cli.world.recompile import Built, commit, ground, rebuild
from twin_cli.world.respec import keep_spec
from twin_cli.world.state import WorldState
from twin_cli.world.values import SpawnResult

if TYPE_CHECKING:
    from twin_cli.world import decomposing

MAX_BATCH = 1000  # instances per request: a guard against a runaway script, not a model limit


@dataclass(frozen=True)
class Placed:
    """Where one instance started: its pose (after on-ground placement) and state at rest."""

    pose: Pose
    state: EntityState


def batch_names(base: str, count: int) -> list[str]:
    """Gazebo-style instance names `base_0`, `base_1`, … for `count` poses."""
    return [f"{base}_{i}" for i in range(count)]


def safe_base(default: str) -> str:
    """A robot's own name made usable as an entity name (`names.as_entity_name`)."""
    from twin_cli.names import as_entity_name

    return as_entity_name(default)


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
        check_finite(pose, f"pose {i} of entity [{name}]")


def conversion_warnings(report: dict | None) -> list[str]:
    """The converter's warnings (what it left out or could not honour), for the terminal: the
    JSON report alone is not where a user looks."""
    entries = (report or {}).get("entries", [])
    return [f"{e['subject']}: {e['detail']}" for e in entries if e.get("outcome") == "warning"]


def make_entity(
    name: str, loaded: spawn.LoadedSource, request: SpawnRequest, placed: Placed
) -> Entity:
    """The one place an entity's record is built: from its request and what was loaded."""
    return Entity(
        name,
        loaded.source,
        request,
        placed.pose,
        placed.state,
        loaded.report,
        loaded.xml,
        loaded.description,
        sensors=loaded.sensors,
        plugins=loaded.plugins,
    )


def spawn_one(
    state: WorldState,
    request: SpawnRequest | object,
    *,
    name: str | None = None,
    pose: Pose = Pose(),
) -> SpawnResult:
    """Adds one entity at `pose`; existing entities keep their exact state.

    `request` is a `SpawnRequest` or a bare source (a path or an MjSpec). Without `name`,
    the robot's own name is used, with `_1`, `_2`, … when taken. The entity starts at rest
    in its own initial configuration (its `home` key if it has one) with the request's
    `joints` written over it; mimic followers follow their leaders. That start is its spawn
    state (what `reset` returns to). Returns once the entity is in the world; in a world server,
    convex hulls may stand in for collision meshes still decomposing (`decomposing`).

    Raises:
        EntityExistsError: `name` is taken. SpawnError: unreadable source or compile error.
        PartNotFoundError: a `joints` name is not a hinge/slide joint of the entity.
        InvalidRequestError: a `joints` value is outside its joint's range (or sets a mimic
            follower). On any error the world is unchanged.
        converters.ConversionError: the converter refused the file.
    """
    request = as_request(request)
    if name is not None:
        spawn.check_entity_name(name)
    loaded = spawn.load_source(request, defer=True)
    with state.lock:
        name = name or free_name(state, safe_base(loaded.default_name))
        result = _spawn_loaded(state, [loaded], request, [name], [pose])[0]
        _decompose_deferred(state, loaded, request, [name])
        return result


def spawn_batch(
    state: WorldState,
    request: SpawnRequest | object,
    *,
    poses: Sequence[Pose],
    names: Sequence[str] | None = None,
    base: str | None = None,
) -> list[SpawnResult]:
    """Adds one entity per pose, converting the source once and compiling the world once.

    Instances are named `names`, else `base_0`, `base_1`, … (`base` defaults to the robot's
    own name). Each starts as `spawn_one` would start it. Raises what `spawn_one` raises, plus
    `check_batch`'s errors; on any error no instance is added and the world is unchanged.
    """
    request, poses = as_request(request), list(poses)
    if names is None and base is not None:
        names = batch_names(spawn.check_entity_name(base), len(poses))
    if names is not None:
        check_batch(list(names), poses, list(state.entities))
    loaded = spawn.load_source(request, defer=True)
    names = list(names or batch_names(safe_base(loaded.default_name), len(poses)))
    copies = [replace(loaded, spec=loaded.spec.copy()) for _ in poses]
    with state.lock:
        results = _spawn_loaded(state, copies, request, names, poses)
        _decompose_deferred(state, loaded, request, names)
        return results


def _decompose_deferred(
    state: WorldState, loaded: spawn.LoadedSource, request: SpawnRequest, names: list[str]
) -> None:
    """Start the background CoACD of a load whose hulls stand in for it (`decomposing`, imported
    only then)."""
    if not loaded.deferred:
        return
    from twin_cli.world import decomposing

    decomposing.start(state, loaded, request, names)


def spawn_specs(
    state: WorldState,
    items: Sequence[tuple[mujoco.MjSpec | spawn.LoadedSource, str, Pose]],
    redo: Mapping[str, decomposing.Convert] | None = None,
) -> list[SpawnResult]:
    """Adds one entity per (model, name, pose) in one compile of the world: a world file's
    models, each an MjSpec or an already converted source (which keeps its file, sensors and
    plugins). One spawn each would compile the world once per model, a cost that grows with
    the square of their number (800 boxes: 77 s). All or nothing, as `spawn_batch`. `redo`:
    entity name → its full conversion, for each model whose hulls stand in for decompositions
    (`decomposing.start_models`)."""
    names = [spawn.check_entity_name(name) for _, name, _ in items]
    poses = [pose for _, _, pose in items]
    loaded = [_loaded(model) for model, _, _ in items]
    requests = [SpawnRequest(source=one.spec) for one in loaded]
    with state.lock:
        results = _spawn_loaded(state, loaded, requests, names, poses)
        redo = redo or {}
        later = [(n, one, redo[n]) for n, one in zip(names, loaded, strict=True) if n in redo]
        if later:
            from twin_cli.world import decomposing

            decomposing.start_models(state, later)
        return results


def _loaded(model: mujoco.MjSpec | spawn.LoadedSource) -> spawn.LoadedSource:
    if isinstance(model, spawn.LoadedSource):
        return replace(model, spec=model.spec.copy())
    return spawn.load_source(SpawnRequest(source=model))


def free_name(state: WorldState, base: str) -> str:
    """`base`, or `base_1`, `base_2`, … when taken."""
    candidate, k = base, 0
    while candidate in state.entities:
        k += 1
        candidate = f"{base}_{k}"
    return candidate


def _spawn_loaded(
    state: WorldState,
    loaded: Sequence[spawn.LoadedSource],
    requests: SpawnRequest | Sequence[SpawnRequest],
    names: Sequence[str],
    poses: Sequence[Pose],
) -> list[SpawnResult]:
    """Attaches each loaded source as its name at its pose, compiles once, seeds each."""
    if isinstance(requests, SpawnRequest):
        requests = [requests] * len(names)
    with state.lock:
        check_batch(names, poses, list(state.entities), limit=max(MAX_BATCH, len(poses)))
        try:
            homes = [
                _attach(state, one, n, p) for one, n, p in zip(loaded, names, poses, strict=True)
            ]
            placed, (model, data, index) = _seed(
                state, loaded[0].source, requests, names, poses, homes
            )
            results, records = [], {}
            for one, request, n, start in zip(loaded, requests, names, placed, strict=True):
                records[n] = make_entity(n, one, request, start)
                starting = placement.start_warnings(model, data, index, n, start.pose.z)
                warnings = [*one.notes, *conversion_warnings(one.report), *starting]
                results.append(SpawnResult(n, one.source, warnings, one.report, one.cached))
        except BaseException:
            for n in names:
                attach.remove_entity(state.spec, n)
            raise
        state.entities.update(records)  # nothing is recorded until everything succeeded
        commit(state, state.spec, (model, data, index))
        hold_from_load(state, names)
        return results


def _attach(
    state: WorldState, loaded: spawn.LoadedSource, name: str, pose: Pose
) -> np.ndarray | None:
    """Attaches the loaded spec to the world spec as `name`; returns its home qpos or None."""
    try:
        home = attach.prepare_child(loaded.spec, state.spec)
        keep_spec(state, name, loaded.spec, loaded.mesh_keys)  # for renew_spec
        shared_meshes.prepare(loaded.spec, state.spec, loaded.mesh_keys)
        attach.attach(state.spec, loaded.spec, name, pose)
    except ValueError as exc:
        raise SpawnError(
            name, loaded.source, f"cannot be attached ({exc})", "fix the model"
        ) from exc
    return home


def _seed(
    state: WorldState,
    source: str,
    requests: Sequence[SpawnRequest],
    names: Sequence[str],
    poses: Sequence[Pose],
    homes: Sequence[np.ndarray | None],
) -> tuple[list[Placed], Built]:
    """One compile of the world with every instance attached; each seeded at rest."""
    kept = [n for n in state.entities if n in state.index]
    model, data, index = rebuild(state, state.spec, names, source)
    starts: list[tuple[Pose, np.ndarray]] = []
    for request, n, pose, home in zip(requests, names, poses, homes, strict=True):
        ix = index[n]
        targets = posture.joint_targets(model, ix.joints, f"{n}/", dict(request.joints), n)
        q = posture.apply_targets(attach.initial_qpos(model, ix, home, pose), ix.qpos, targets)
        if request.on_ground:  # a fixed base moves its frame: a recompile, layouts kept
            pose, q, (model, data, _) = ground(state, (model, data, index), n, pose, q)
            index = index_entities(model, kept + list(names))
        starts.append((pose, q))
    placed = []
    for n, (pose, q) in zip(names, starts, strict=True):
        at_rest = rest_state(model, index[n], q)
        write_state(data, index[n], at_rest)
        placed.append(Placed(pose, at_rest))
    return placed, (model, data, index)
