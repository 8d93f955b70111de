"""CoACD convex decomposition in worker processes: parallel, time-limited, crash-proof.

CoACD is C++ that can abort the whole process on some inputs, so every mesh is
decomposed in its own child process (`converters.collision.worker`), started with
`subprocess` rather than `multiprocessing`: no re-import of the caller's `__main__`, no fork
of a process that may run server threads. Job and result travel as .npz files in a private
temporary directory, so a child never blocks on a full pipe. A child that dies (abort,
segfault, kill), exits with an error, or outlives its time limit (it is killed) yields a
`DecomposeOutcome` with `failure` set and no parts; the caller falls back to the convex hull.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from converters.collision.cache import unpack_parts

# Test-only hook: "<fault>:<request key>" (or "<fault>:*"), comma-separated, makes the worker
# for that mesh misbehave (fault = crash | kill | abort | hang | error), so tests exercise real
# processes dying and hanging.
FAULT_ENV = "TWIN_TEST_COACD_FAULT"
FAULTS = ("crash", "kill", "abort", "hang", "error")
# How often the parent looks at running workers [s].
POLL_S = 0.02


@dataclass(frozen=True)
class DecomposeJob:
    """One mesh to decompose: `params` are `coacd.run_coacd` keyword arguments."""

    key: str
    vertices: np.ndarray
    faces: np.ndarray
    params: dict[str, Any]
    fault: str | None = None


@dataclass(frozen=True)
class DecomposeOutcome:
    """What became of one job: parts as (vertices [m], faces) pairs, or a failure reason.

    `timed_out` marks a worker stopped at the time limit: the same mesh, parameters and limit
    would time out again, so that fallback may be cached; a crash may come from outside
    (out-of-memory killer, Ctrl-C), so it is retried.
    """

    key: str
    parts: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0
    failure: str | None = None
    timed_out: bool = False


@dataclass
class _Running:
    job: DecomposeJob
    process: subprocess.Popen
    result: Path
    errors: Path
    started: float


def default_jobs() -> int:
    """All cores this process may use."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def fault_for(key: str) -> str | None:
    """The fault the test hook asks for on `key` ("*" matches every key), else None."""
    for item in os.environ.get(FAULT_ENV, "").split(","):
        fault, _, target = item.strip().partition(":")
        if fault in FAULTS and target in (key, "*"):
            return fault
    return None


def _start(job: DecomposeJob, index: int, workdir: Path, threads: int) -> _Running:
    job_path, result = workdir / f"job{index}.npz", workdir / f"result{index}.npz"
    np.savez(
        job_path,
        vertices=np.asarray(job.vertices, np.float64),
        faces=np.asarray(job.faces, np.int32),
        params=np.array(json.dumps(job.params)),
        fault=np.array(job.fault or ""),
    )
    errors = workdir / f"errors{index}.txt"
    env = {**os.environ, "OMP_NUM_THREADS": str(threads)}  # libgomp reads it when coacd loads
    with open(errors, "wb") as err:
        process = subprocess.Popen(
            [sys.executable, "-m", "converters.collision.worker", str(job_path), str(result)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=err,
            env=env,
        )
    return _Running(job, process, result, errors, time.perf_counter())


def _collect(run: _Running) -> DecomposeOutcome:
    """Turn a finished worker's exit status and files into an outcome."""
    elapsed = time.perf_counter() - run.started
    code = run.process.returncode
    if code == 0 and run.result.exists():
        with np.load(run.result, allow_pickle=False) as data:
            parts = unpack_parts(data, int(data["count"]))
        return DecomposeOutcome(run.job.key, parts=parts, seconds=elapsed)
    if code is not None and code < 0:
        failure = f"CoACD worker killed by signal {signal.Signals(-code).name}"
    else:
        tail = run.errors.read_text(errors="replace").strip().splitlines()[-1:]
        failure = f"CoACD worker exited with status {code}" + (f": {tail[0]}" if tail else "")
    return DecomposeOutcome(run.job.key, seconds=elapsed, failure=failure)


def _kill(run: _Running, time_limit: float) -> DecomposeOutcome:
    run.process.kill()
    run.process.wait()
    reason = f"CoACD exceeded the {time_limit:g} s time limit and was stopped"
    seconds = time.perf_counter() - run.started
    return DecomposeOutcome(run.job.key, seconds=seconds, failure=reason, timed_out=True)


def decompose_all(
    jobs: list[DecomposeJob],
    *,
    workers: int | None = None,
    time_limit: float = 20.0,
    on_done: Callable[[DecomposeOutcome], None] | None = None,
) -> dict[str, DecomposeOutcome]:
    """Decompose every job, at most `workers` at a time, each in its own process.

    Args:
        jobs: meshes to decompose.
        workers: processes at once (default: all cores); each gets cores // workers OpenMP
            threads, so a single worker still uses the whole machine.
        time_limit: seconds one mesh may take before its worker is killed [s].
        on_done: called in this process as each job finishes (progress display).

    Returns:
        One outcome per job key. Never raises for a worker that fails.
    """
    if not jobs:
        return {}
    workers = max(1, min(workers or default_jobs(), len(jobs)))
    threads = max(1, default_jobs() // workers)
    pending, running, done = deque(enumerate(jobs)), [], {}
    with tempfile.TemporaryDirectory(prefix="twin-coacd-") as tmp:
        try:
            while pending or running:
                while pending and len(running) < workers:
                    index, job = pending.popleft()
                    running.append(_start(job, index, Path(tmp), threads))
                time.sleep(POLL_S)
                for run in list(running):
                    outcome = _check(run, time_limit)
                    if outcome is not None:
                        running.remove(run)
                        done[outcome.key] = outcome
                        if on_done is not None:
                            on_done(outcome)
        finally:  # an error or Ctrl-C here must not leave CoACD processes behind
            for run in running:
                run.process.kill()
                run.process.wait()
    return done


def _check(run: _Running, time_limit: float) -> DecomposeOutcome | None:
    """The outcome of a worker that has finished or overrun, else None (still working)."""
    if run.process.poll() is not None:
        return _collect(run)
    if time.perf_counter() - run.started > time_limit:
        return _kill(run, time_limit)
    return None
