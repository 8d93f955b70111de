"""Collision meshes decomposed in the background while a served world steps, then swapped in.

A served spawn (`spawn.load_source` with `defer`) whose CoACD meshes the collision cache lacks
spawns at once, each such mesh's convex hull standing in for its decomposition. `start` then
runs the full conversion on a thread of its own, in a bounded child as any served conversion:
each mesh within its CoACD CPU budget (`--coacd-cpu-limit`) and its wall-clock backstop, the
child within the served wall limit plus every deferred mesh's backstop (the fixed served limit
alone would stop a robot of several slow meshes on a busy machine, while nobody waits for it).
The result goes to the conversion cache and the collision cache on disk, as a spawn's does.

When it is ready the thread takes the world's lock, which the stepping loop holds for one batch
of steps at a time, so the swap falls between two batches: the world spec is rebuilt with each
waiting entity's spec replaced by the decomposed one (`respec.fresh_spec`, entities in spawn
order, frames where they are) and recompiled, every entity's state carried over by name, as a
spawn of another entity does. Nothing runs per step.

A description sent as text is converted again from the text the request keeps. Spawns of
one conversion (equal `job_key`: the conversion cache's key, or the text's digest) share one
job while it is pending: a second spawn of a file still decomposing waits for the first's job
and is swapped by it, so CoACD runs once. A world file's models (`start_models`) each have a
job of their own, run one after another on one thread (`world_models` converts each in full),
and each model is swapped in as soon as its own is ready.

Each entity's `Decomposition` says where it is: pending, done (no hull stands in any more),
or failed (a hull stays: CoACD over its budget, crashed, or the conversion failed; the entity's
report rows say why). A delete of every entity waiting for a decomposition cancels it: its
child and CoACD workers are killed.
"""

from __future__ import annotations

import hashlib
import logging
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import attach, respec, spawn
from twin_cli.world.recompile import commit, rebuild
from twin_cli.world.values import DEFERRED_STOP, deferred_meshes, hull_stand_ins

if TYPE_CHECKING:
    from twin_cli.world.state import WorldState

log = logging.getLogger(__name__)

PENDING, DONE, FAILED = "pending", "done", "failed"


Convert = Callable[[spawn.Served], spawn.LoadedSource]  # a full conversion, run as served


@dataclass(eq=False)
class Decomposition:
    """One background decomposition: the spawn's source and request, the mesh keys it
    decomposes, what it converts (`key`, `job_key`), how (`convert`; None: the request's
    description again), where it is (`status`), why it failed (`detail`), its cancel event."""

    source: str
    request: SpawnRequest
    meshes: tuple[str, ...]
    key: tuple = ()
    convert: Convert | None = None
    status: str = PENDING
    detail: str = ""
    cancel: threading.Event = field(default_factory=threading.Event)


def start(
    state: WorldState, loaded: spawn.LoadedSource, request: SpawnRequest, names: Sequence[str]
) -> None:
    """Starts decomposing a deferred spawn's meshes for entities `names` (lock held; they are
    in the world), or lets them wait for a pending job of the same conversion; nothing when
    `loaded` deferred nothing."""
    if not loaded.deferred:
        return
    key = job_key(request)
    job = next((j for j in state.decompositions.values() if j.key == key and _open(j)), None)
    if job is None:
        job = Decomposition(loaded.source, request, deferred_meshes(loaded.report), key)
        _launch(state, [job], names[0])
    for name in names:
        state.decompositions[name] = job


def start_models(
    state: WorldState, models: Sequence[tuple[str, spawn.LoadedSource, Convert]]
) -> None:
    """Starts decomposing a world file's deferred models, (entity name, what was loaded, its
    full conversion) each, one after another on one thread (lock held; they are in the world)."""
    jobs = []
    for name, loaded, convert in models:
        if loaded.deferred:
            meshes = deferred_meshes(loaded.report)
            job = Decomposition(loaded.source, SpawnRequest(), meshes, (loaded.source,), convert)
            state.decompositions[name] = job
            jobs.append(job)
    if jobs:
        _launch(state, jobs, "world")


def job_key(request: SpawnRequest) -> tuple:
    """What a spawn's conversion is, besides its files' contents: equal for two spawns that
    convert alike (a file: the conversion cache's key; a text: its digest and base folder)."""
    from twin_cli.world.conversion_cache import cache_key

    env = spawn.resolving_env(request)
    if request.xml is None:
        return cache_key(Path(request.source).expanduser().resolve(), request, env)
    digest = hashlib.blake2b(request.xml.encode(), digest_size=20).hexdigest()
    return (*cache_key(Path(request.base_dir or "."), request, env), digest)


def _open(job: Decomposition) -> bool:
    """Whether another entity may still wait for `job`: pending and not cancelled (a job
    whose entities were all deleted is cancelled, though its thread may not have seen it)."""
    return job.status == PENDING and not job.cancel.is_set()


def _launch(state: WorldState, jobs: Sequence[Decomposition], label: str) -> None:
    """Runs `jobs` one after another on a thread of their own."""
    thread = threading.Thread(
        target=_run_all, args=(state, jobs), name=f"twin-decompose-{label}", daemon=True
    )
    thread.start()


def status(state: WorldState, name: str) -> str | None:
    """Where entity `name`'s background decomposition is, or None if it had none (lock held)."""
    job = state.decompositions.get(name)
    return None if job is None else job.status


def forget(state: WorldState, name: str) -> None:
    """After entity `name` was deleted (lock held): its decomposition is cancelled when no
    other entity waits for it."""
    job = state.decompositions.pop(name, None)
    if job is not None and job.status == PENDING and job not in state.decompositions.values():
        job.cancel.set()


def cancel_all(state: WorldState, reason: str) -> None:
    """Cancels every pending decomposition; each keeps its hulls, `reason` saying why (lock
    held)."""
    for job in {id(job): job for job in state.decompositions.values()}.values():
        if job.status == PENDING:
            job.cancel.set()
            _fail(state, job, reason)


def backstop_s(request: SpawnRequest, meshes: int) -> float:
    """Wall time [s] to allow a decomposition over the served budget: every deferred mesh's
    CoACD wall-clock backstop, one after another (the worst case: one worker at a time)."""
    from converters.collision.decompose import Limits
    from converters.collision.plan import default_cpu_limit

    cpu = request.coacd_cpu_limit or default_cpu_limit()
    return meshes * Limits.for_cpu(cpu).wall


def _run_all(state: WorldState, jobs: Sequence[Decomposition]) -> None:
    """The thread: each job not cancelled meanwhile, in turn."""
    for job in jobs:
        if not job.cancel.is_set():
            _run(state, job)


def _run(state: WorldState, job: Decomposition) -> None:
    """The thread: convert in full, then swap the result in, or say why not."""
    try:
        loaded = _convert(job)
    except Exception as exc:  # noqa: BLE001 (any failure keeps the hull and is said)
        if not job.cancel.is_set():
            with state.lock:
                _fail(state, job, str(exc) or type(exc).__name__)
        return
    with state.lock:
        names = _waiting(state, job)
        if not names or job.cancel.is_set():
            return
        try:
            swap(state, names, loaded)
        except Exception as exc:  # noqa: BLE001 (a swap that fails leaves the world as it was)
            _fail(state, job, f"the decomposed model could not be swapped in ({exc})")
            return
        stand_ins = hull_stand_ins(loaded.report)
        job.status = FAILED if stand_ins else DONE
        job.detail = "; ".join(stand_ins)
        log.info("%s: decomposition %s for %s", job.source, job.status, ", ".join(names))


def _convert(job: Decomposition) -> spawn.LoadedSource:
    """The full conversion: `job.convert`, a text's, or a file's from (and into) the
    conversion cache."""
    from twin_cli.world.conversion_cache import CACHE

    served = spawn.Served(extra_s=backstop_s(job.request, len(job.meshes)), cancel=job.cancel)
    if job.convert is not None:
        return job.convert(served)
    if job.request.xml is not None:
        return spawn.convert_text(job.request, served)
    path = Path(job.source)
    return CACHE.load(job.key, lambda: spawn.convert_description(path, job.request, served))


def _waiting(state: WorldState, job: Decomposition) -> list[str]:
    """The entities still waiting for `job` (a deleted one's name may be taken again)."""
    return [name for name, each in state.decompositions.items() if each is job]


def swap(state: WorldState, names: Sequence[str], loaded: spawn.LoadedSource) -> None:
    """Replaces entities `names`' specs with `loaded`'s, keeping every entity's state (lock
    held). Raises what a compile raises, or ValueError when an entity's layout changed; the
    world is then unchanged."""
    children = {}
    for name in names:
        child = loaded.spec.copy()
        attach.prepare_child(child, state.spec)
        children[name] = (child, loaded.mesh_keys)
    fresh = respec.fresh_spec(state, children)
    if fresh is None:
        raise ValueError("the world spec cannot be rebuilt")
    built = rebuild(state, fresh, (), loaded.source, from_scratch=True)
    _check_layout(state, built[2], names)
    commit(state, fresh, built)
    for name in names:
        respec.keep_spec(state, name, *children[name])
        # a text's or a world model's MJCF (what a save writes) is the decomposed one now
        state.entities[name] = replace(state.entities[name], report=loaded.report, xml=loaded.xml)


def _check_layout(state: WorldState, index: dict, names: Sequence[str]) -> None:
    """Raises ValueError when an entity's joints, actuators or bodies changed in number."""
    for name in names:
        old, new = state.index[name], index[name]
        for part in ("bodies", "qpos", "dofs", "actuators", "acts", "equalities", "mocaps"):
            if len(getattr(old, part)) != len(getattr(new, part)):
                raise ValueError(f"entity [{name}]'s {part} changed")


def _fail(state: WorldState, job: Decomposition, reason: str) -> None:
    """Keeps the hulls of `job`'s entities and says why in their reports (lock held)."""
    job.status, job.detail = FAILED, reason
    log.warning("%s: background decomposition failed, hulls kept: %s", job.source, reason)
    for name in _waiting(state, job):
        entity = state.entities[name]
        state.entities[name] = replace(entity, report=_failed_report(entity.report, reason))


def _failed_report(report: dict | None, reason: str) -> dict | None:
    """`report` with each deferred mesh's row saying that its decomposition failed."""
    if report is None:
        return None
    rows = [
        {**row, "fallback": f"background decomposition failed: {reason}", "stopped": None}
        if row.get("stopped") == DEFERRED_STOP
        else row
        for row in report.get("meshes", [])
    ]
    return {**report, "meshes": rows}
