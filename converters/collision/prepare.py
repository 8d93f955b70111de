"""Carrying out the collision plan: cache look-ups, hulls, CoACD jobs, fallbacks, report rows.

Each mesh gets one row in `report.meshes`:
`key, link, source, requested, mode, reason, triangles_before, triangles_after, parts,
volume_reference ("mesh" when the mesh is closed, else "hull"), volume_ratio (sum of part
volumes / reference volume), seconds (this run), compute_seconds (when first computed),
cpu_seconds (CPU time of the CoACD call, else None), cache ("hit" | "miss" | "off"),
fallback (why the hull stands in for CoACD's parts, else None)`, and one line in
`report.entries`. `report.summary["collision"]` totals them.

Cache: a result is stored under its content key (mesh bytes, scale, mode, CoACD parameters),
and so is "CoACD returned no usable part", which the same bytes and parameters always give.
A hull standing in for a decomposition that did not finish is never stored, so every
conversion tries again: a worker over its CPU budget (CPU time varies from run to run, by up
to a third on a shared virtual machine, so a mesh near its budget may finish next time, and a
larger budget must get the real parts), past the wall-clock backstop, or dead (out-of-memory
kill, Ctrl-C); nor is the hull given for a mesh left to a later conversion
(`CollisionSettings.defer`, row `stopped` "deferred").
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from converters.collision import cache as mesh_cache
from converters.collision import hulls
from converters.collision.decompose import (
    DecomposeJob,
    DecomposeOutcome,
    Limits,
    Stop,
    decompose_all,
    fault_for,
)
from converters.collision.plan import (
    CONVEX_RATIO,
    TRIANGLES_ADVISED,
    TRIANGLES_MAX,
    CoacdParams,
    CollisionMode,
    CollisionRequest,
    CollisionSettings,
    Decision,
    MeshPart,
    check_settings,
    coacd_params,
    decide,
    requested_mode,
)
from converters.collision.progress import MeshProgress
from converters.report import Report

Pairs = list[tuple[np.ndarray, np.ndarray]]
# What to do about a mesh that did not finish within its CPU budget [CPU s].
CPU_HINT = (
    "; not cached: give it more CPU time (--coacd-cpu-limit, now {limit:g} CPU s) or, in"
    " `twin convert`, a cheaper search (--coacd-preset fast, a larger --coacd-threshold) or"
    " --collision-link {link}=hull"
)
# Why a mesh left to a later conversion (`CollisionSettings.defer`) has its hull for now.
DEFERRED = "CoACD decomposition not run yet (it runs in the background)"
ROW_FIELDS = (
    "key",
    "link",
    "source",
    "requested",
    "mode",
    "reason",
    "triangles_before",
    "triangles_after",
    "parts",
    "volume_reference",
    "volume_ratio",
    "seconds",
    "compute_seconds",
    "cpu_seconds",
    "cache",
    "fallback",
    "stopped",
)


@dataclass(frozen=True)
class _Plan:
    """One mesh on its way: what was asked, what was decided, and the facts for its row."""

    request: CollisionRequest
    requested: CollisionMode
    decision: Decision
    params: CoacdParams
    volume_reference: tuple[str, float]
    content_key: str
    use_cache: bool
    started: float


def prepare(
    requests: list[CollisionRequest], settings: CollisionSettings, report: Report
) -> dict[str, list[MeshPart]]:
    """See `converters.collision.plan.prepare_collision_meshes` (settings already checked)."""
    started = time.perf_counter()
    results: dict[str, Pairs] = {}
    rows: dict[str, dict[str, Any]] = {}
    waiting: dict[str, list[_Plan]] = {}  # content key -> meshes with those bytes
    with MeshProgress(len(requests), enabled=settings.progress) as progress:
        for request in requests:
            plan, cached = _plan(request, settings)
            if plan is not None and plan.decision.mode is CollisionMode.COACD and cached is None:
                if settings.defer:
                    results[request.key], rows[request.key] = _deferred(plan)
                    progress.advance(_label(rows[request.key]))
                    continue
                waiting.setdefault(plan.content_key, []).append(plan)
                continue
            results[request.key], rows[request.key] = cached or _without_coacd(request, plan)
            progress.advance(_label(rows[request.key]))

        def finished(outcome: DecomposeOutcome) -> None:
            for plan in waiting[outcome.key]:
                key = plan.request.key
                results[key], rows[key] = _from_outcome(plan, outcome)
                progress.advance(_label(rows[key]))

        jobs = [_job(plans) for plans in waiting.values()]
        limits = Limits.for_cpu(settings.cpu_limit, settings.wall_limit)
        decompose_all(jobs, workers=settings.jobs, limits=limits, on_done=finished)
    ordered = [rows[r.key] for r in requests]
    _report(ordered, settings, report, len(jobs), time.perf_counter() - started)
    return {r.key: [MeshPart(v, f) for v, f in results[r.key]] for r in requests}


def _plan(
    request: CollisionRequest, settings: CollisionSettings
) -> tuple[_Plan | None, tuple[Pairs, dict[str, Any]] | None]:
    """Decide one mesh's mode; return (plan, None) to compute or (None|plan, cached result)."""
    started = time.perf_counter()
    requested = requested_mode(request, settings)
    params = coacd_params(request, settings)
    if requested is CollisionMode.MESH:
        return None, None
    key = _cache_key(request, requested, params)
    hit = mesh_cache.load(key) if settings.use_cache else None
    if hit is not None:  # the entry may come from another link with the same mesh bytes
        own = {"key": request.key, "link": request.link, "source": request.source}
        row = {**hit.meta, **own, "cache": "hit", "seconds": time.perf_counter() - started}
        return None, (hit.parts, {name: row.get(name) for name in ROW_FIELDS})
    try:
        volumes = hulls.volumes(request.vertices, request.faces)
    except Exception:  # qhull rejects flat or tiny point sets; the builder gets no parts
        volumes = hulls.MeshVolumes(mesh=None, hull=0.0)
    decision = _decision(request, requested, volumes)
    reference = ("mesh", volumes.mesh) if volumes.mesh is not None else ("hull", volumes.hull)
    plan = _Plan(
        request,
        requested,
        decision,
        params,
        reference,
        key,
        settings.use_cache,
        started,
    )
    return plan, None


def _decision(
    request: CollisionRequest, requested: CollisionMode, volumes: hulls.MeshVolumes
) -> Decision:
    if volumes.hull <= hulls.MIN_PART_VOLUME:
        return Decision(CollisionMode.HULL, "flat or degenerate mesh: no volume to collide with")
    if requested is CollisionMode.AUTO:
        return decide(len(request.faces), volumes.convexity)
    return Decision(requested, f"--collision {requested.value}", volumes.convexity)


def _cache_key(request: CollisionRequest, requested: CollisionMode, params: CoacdParams) -> str:
    """The content key: what the result is a function of (no budget: a result is a result)."""
    facts = {
        "time_limit": None,  # kept: entries written by earlier versions stay valid
        "mode": requested.value,
        "scale": list(request.scale),
        "params": params.kwargs(),
        "rule": [CONVEX_RATIO, TRIANGLES_ADVISED, TRIANGLES_MAX, hulls.MIN_PART_VOLUME],
    }
    return mesh_cache.entry_key(request.vertices, request.faces, facts)


def _job(plans: list[_Plan]) -> DecomposeJob:
    """One CoACD run for every mesh with the same bytes and parameters."""
    first = plans[0]
    faults = [fault_for(plan.request.key) for plan in plans]
    return DecomposeJob(
        key=first.content_key,
        vertices=first.request.vertices,
        faces=first.request.faces,
        params=first.params.kwargs(),
        fault=next((f for f in faults if f), None),
    )


def _without_coacd(request: CollisionRequest, plan: _Plan | None) -> tuple[Pairs, dict[str, Any]]:
    """Whole mesh (mode `mesh`) or its capped hull; hull results are cached like CoACD's."""
    if plan is None:
        parts = [(np.asarray(request.vertices, float), np.asarray(request.faces))]
        row = _row(request, "mesh", "mesh", "--collision mesh", parts, ("mesh", 0.0), 0.0)
        row["volume_ratio"] = 1.0
        return parts, row
    parts = _hull_parts(request.vertices, plan.params.max_ch_vertex)
    return parts, _finish(plan, parts, fallback=None, store_key=plan.content_key)


def _hull_parts(vertices: np.ndarray, cap: int) -> Pairs:
    try:
        hull = hulls.convex_hull(vertices, cap)
    except Exception:  # flat: qhull has nothing to wrap
        return []
    return [hull] if hulls.usable_part(*hull) else []


def _deferred(plan: _Plan) -> tuple[Pairs, dict[str, Any]]:
    """The hull standing in for a decomposition left for a later conversion (not stored)."""
    parts = _hull_parts(plan.request.vertices, plan.params.max_ch_vertex)
    row = _finish(plan, parts, DEFERRED, store_key=None, worker={"stopped": Stop.DEFERRED.value})
    return parts, row


def _from_outcome(plan: _Plan, outcome: DecomposeOutcome) -> tuple[Pairs, dict[str, Any]]:
    """Capped CoACD parts, or the hull when the worker failed or left nothing usable."""
    cap = plan.params.max_ch_vertex
    parts = [hulls.convex_hull(v, cap) for v, f in outcome.parts if hulls.usable_part(v, f)]
    failure, store_key = outcome.failure, plan.content_key
    if failure is None and not parts:
        failure = "CoACD returned no usable part"
    elif failure is not None:
        store_key = None  # did not finish: budget, backstop or death; tried again next time
    if failure is not None:
        parts = _hull_parts(plan.request.vertices, cap)
    stopped = None if outcome.stopped is None else outcome.stopped.value
    worker = {"seconds": outcome.seconds, "cpu_seconds": outcome.cpu_seconds, "stopped": stopped}
    row = _finish(plan, parts, failure, store_key=store_key, worker=worker)
    return parts, row


def _finish(
    plan: _Plan,
    parts: Pairs,
    fallback: str | None,
    *,
    store_key: str | None,
    worker: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Build the row and store the result under `store_key` (None: not stored); `worker`
    gives a CoACD worker's `seconds`, `cpu_seconds` and `stopped` for the row."""
    mode = CollisionMode.HULL if fallback else plan.decision.mode
    seconds = time.perf_counter() - plan.started
    row = _row(
        plan.request,
        plan.requested.value,
        mode.value,
        plan.decision.reason,
        parts,
        plan.volume_reference,
        seconds,
    )
    # A CoACD mesh is timed by its worker (not the wait in the queue behind other meshes).
    row.update(worker or {}, fallback=fallback, cache="miss" if plan.use_cache else "off")
    row["compute_seconds"] = row["seconds"]
    if plan.use_cache and store_key is not None:
        meta = {k: v for k, v in row.items() if k not in ("cache", "seconds")}
        try:
            mesh_cache.store(store_key, parts, meta)
        except OSError as exc:
            row["cache"] = f"not stored: {exc}"
    return row


def _row(
    request: CollisionRequest,
    requested: str,
    mode: str,
    reason: str,
    parts: Pairs,
    reference: tuple[str, float],
    seconds: float,
) -> dict[str, Any]:
    total = sum(hulls.hull_volume((np.asarray(v), np.asarray(f))) for v, f in parts)
    ratio = total / reference[1] if reference[1] > 0 else None
    return {
        "key": request.key,
        "link": request.link,
        "source": request.source,
        "requested": requested,
        "mode": mode,
        "reason": reason,
        "triangles_before": int(len(request.faces)),
        "triangles_after": int(sum(len(f) for _, f in parts)),
        "parts": len(parts),
        "volume_reference": reference[0],
        "volume_ratio": ratio,
        "seconds": seconds,
        "compute_seconds": seconds,
        "cpu_seconds": None,
        "cache": "off",
        "fallback": None,
        "stopped": None,
    }


def _label(row: dict[str, Any]) -> str:
    return f"{row['key']} {row['mode']} {row['parts']} parts ({row['cache']})"


def _report(
    rows: list[dict[str, Any]],
    settings: CollisionSettings,
    report: Report,
    runs: int,
    seconds: float,
) -> None:
    """One report line per mesh, the rows, and the totals."""
    for row in rows:
        subject = f"link '{row['link']}' collision mesh {Path(row['source']).name}"
        report.meshes.append(row)
        if row["fallback"]:
            hint = _hint(row, settings)
            report.warn(subject, f"{row['fallback']}; its convex hull stands in for it{hint}")
        elif row["parts"] == 0:
            report.warn(subject, f"{row['reason']}; left out of collision")
        else:
            report.approximated(subject, _describe(row, settings.preset))
    report.summary["collision"] = {
        "meshes": len(rows),
        "coacd_runs": runs,
        "cache_hits": sum(row["cache"] == "hit" for row in rows),
        "fallbacks": sum(bool(row["fallback"]) for row in rows),
        "coacd_cpu_seconds": sum(
            row["cpu_seconds"] or 0.0 for row in rows if row["cache"] != "hit"
        ),
        "parts": sum(row["parts"] for row in rows),
        "seconds": seconds,
    }


def _hint(row: dict[str, Any], settings: CollisionSettings) -> str:
    """What to do about a fallback: for a spent CPU budget, the options that change it."""
    if row.get("stopped") == Stop.DEFERRED.value:
        return " until then (`twin list` shows when the decomposition is swapped in)"
    if row.get("stopped") == Stop.CPU.value:
        return CPU_HINT.format(limit=settings.cpu_limit, link=row["link"])
    return ""


def _describe(row: dict[str, Any], preset: str) -> str:
    ratio = row["volume_ratio"]
    volume = "" if ratio is None else f"; {ratio:.2f}x the {row['volume_reference']} volume"
    if row["mode"] == "mesh":
        return "kept whole; MuJoCo collides it as its convex hull"
    if row["mode"] == "hull":
        return f"convex hull, {row['triangles_after']} triangles ({row['reason']}){volume}"
    return f"CoACD ({preset}): {row['parts']} convex parts ({row['reason']}){volume}"


def prepare_collision_meshes(
    requests: list[CollisionRequest], settings: CollisionSettings, report: Report
) -> dict[str, list[MeshPart]]:
    """Return the convex parts for each request key, decomposing in parallel, cached on disk.

    Args:
        requests: every collision mesh of the robot, scaled to metres.
        settings: the user's choices.
        report: receives one line per mesh and `report.meshes` rows (see this module).

    Returns:
        `{request.key: [MeshPart, ...]}`, one MuJoCo geom per part.

    Raises:
        CollisionSettingsError: an unknown mode or preset. A mesh that fails to decompose
            never raises: it falls back to its convex hull and the report says why.
    """
    from converters.isolated.replay import read_once
    from converters.isolated.stages import stage

    check_settings(settings)
    by_key = {r.key: r for r in requests}

    def compute() -> tuple[dict[str, list[MeshPart]], Report]:
        stage(f"preparing {len(requests)} collision meshes (hulls, CoACD)", own_progress=True)
        found = Report()
        return prepare(requests, settings, found), found

    def pack(value: tuple[dict[str, list[MeshPart]], Report]) -> tuple[dict, Report]:
        """A part that is its request's own mesh is kept as None: the builder shares it."""
        parts, found = value
        return {
            k: [None if p.vertices is by_key[k].vertices else p for p in v]
            for k, v in parts.items()
        }, found

    def unpack(kept: tuple[dict, Report]) -> tuple[dict[str, list[MeshPart]], Report]:
        whole = {k: MeshPart(r.vertices, r.faces) for k, r in by_key.items()}
        return {k: [whole[k] if p is None else p for p in v] for k, v in kept[0].items()}, kept[1]

    parts, found = read_once("collision", tuple(by_key), compute, pack=pack, unpack=unpack)
    report.entries.extend(found.entries)  # what was read is said again where it is replayed
    report.meshes.extend(found.meshes)
    report.summary.update(found.summary)
    return parts
