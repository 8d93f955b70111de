"""CoACD convex decomposition in worker processes: parallel, CPU-budgeted, crash-proof.

CoACD is C++ that can abort the whole process on some inputs, so every mesh is
decomposed in its own child process (`converters.collision.worker`), started with
`subprocess` rather than `multiprocessing`: no re-import of the caller's `__main__`, no fork
of a process that may run server threads. Job and result travel as .npz files in a private
temporary directory, so a child never blocks on a full pipe.

A mesh's budget is CPU time, counted by the kernel for the worker's CoACD call alone (all its
threads): the worker arms `ITIMER_PROF`, whose SIGPROF ends it when the budget is spent. CPU
time does not grow with the machine's load the way wall-clock time does (measured on a 16-section
cup, fast preset: 3.0-3.4 CPU s idle and beside two busy loops, while wall time went from 4 s
to 15 s), so a mesh well within its budget is decomposed the same way on an idle and a busy
machine. It is not exact (up to a third more on a shared virtual machine), hence budgets far
above what a mesh needs (`plan.DEFAULT_CPU_LIMIT`). A
wall-clock backstop (`WALL_BACKSTOP_FACTOR` times the budget, at least `WALL_BACKSTOP_MIN_S`)
only catches a worker that hangs without using CPU.

A child that dies (abort, segfault, kill), exits with an error, spends its budget or passes the
backstop yields a `DecomposeOutcome` with `failure` set and no parts; the caller falls back to
the convex hull.
"""

from __future__ import annotations

import enum
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
from converters.collision.plan import DEFAULT_CPU_LIMIT
from converters.collision.worker import CPU_SIGNAL

# Test-only hook: "<fault>:<request key>" (or "<fault>:*"), comma-separated, makes the worker
# for that mesh misbehave (fault = crash | kill | abort | hang | error), so tests exercise real
# processes dying and hanging.
FAULT_ENV = "TWIN_TEST_COACD_FAULT"
FAULTS = ("crash", "kill", "abort", "hang", "error")
# How often the parent looks at running workers [s].
POLL_S = 0.02
# Wall-clock backstop: a worker still running after this many times its CPU budget, and at
# least WALL_BACKSTOP_MIN_S, is taken as hung (two busy loops on two cores stretched a 3 CPU s
# run to 15 s wall; ten times leaves room for a far busier machine) [s].
WALL_BACKSTOP_FACTOR = 10.0
WALL_BACKSTOP_MIN_S = 60.0
# libgomp's idle threads spin by default, burning CPU time that grows with the machine's load;
# passive waiting keeps the CPU time a function of the work (3.27 -> 3.02 CPU s, two threads).
WORKER_ENV = {"OMP_WAIT_POLICY": "PASSIVE"}


class Stop(enum.Enum):
    """Why a worker was stopped before it finished."""

    CPU = "cpu"  # spent its CPU budget: the same mesh and budget stop again on any machine
    WALL = "wall"  # passed the wall-clock backstop: a hang or an overloaded machine
    DEFERRED = "deferred"  # never started: a later conversion decomposes it (`defer`)


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

    `seconds` is the worker's wall time [s], `cpu_seconds` the CPU time of its CoACD call
    [CPU s] (None when it never finished one), `stopped` why it was stopped, if it was.
    """

    key: str
    parts: list[tuple[np.ndarray, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0
    failure: str | None = None
    stopped: Stop | None = None
    cpu_seconds: float | None = None


@dataclass(frozen=True)
class Limits:
    """A worker's budget: `cpu` [CPU s] for CoACD's call, `wall` [s] for the whole process."""

    cpu: float
    wall: float

    @classmethod
    def for_cpu(cls, cpu: float, wall: float | None = None) -> Limits:
        """`cpu` with the default backstop (or the given `wall` [s])."""
        backstop = max(WALL_BACKSTOP_FACTOR * cpu, WALL_BACKSTOP_MIN_S)
        return cls(cpu, backstop if wall is None else wall)


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


def _start(job: DecomposeJob, index: int, workdir: Path, threads: int, cpu: float) -> _Running:
    job_path, result = workdir / f"job{index}.npz", workdir / f"result{index}.npz"
    np.savez(
        job_path,
        vertices=np.asarray(job.vertices, np.float64),
        faces=np.asarray(job.faces, np.int32),
        params=np.array(json.dumps(job.params)),
        fault=np.array(job.fault or ""),
        cpu_limit=np.array(float(cpu)),
    )
    errors = workdir / f"errors{index}.txt"
    # libgomp reads these when coacd loads.
    env = {**os.environ, **WORKER_ENV, "OMP_NUM_THREADS": str(threads)}
    with open(errors, "wb") as err:
        process = subprocess.Popen(
            [sys.executable, "-m", "converters.collision.worker", str(job_path), str(result)],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=err,
            env=env,
        )
    return _Running(job, process, result, errors, time.perf_counter())


def _collect(run: _Running, limits: Limits) -> DecomposeOutcome:
    """Turn a finished worker's exit status and files into an outcome."""
    elapsed = time.perf_counter() - run.started
    code, key = run.process.returncode, run.job.key
    if code == 0 and run.result.exists():
        with np.load(run.result, allow_pickle=False) as data:
            parts = unpack_parts(data, int(data["count"]))
            cpu = float(data["cpu_seconds"])
        return DecomposeOutcome(key, parts=parts, seconds=elapsed, cpu_seconds=cpu)
    if CPU_SIGNAL is not None and code == -CPU_SIGNAL:
        failure = f"CoACD used its {limits.cpu:g} CPU s budget and was stopped"
        return DecomposeOutcome(key, [], elapsed, failure, Stop.CPU, limits.cpu)
    if code is not None and code < 0:
        failure = f"CoACD worker killed by signal {signal.Signals(-code).name}"
    else:
        tail = run.errors.read_text(errors="replace").strip().splitlines()[-1:]
        failure = f"CoACD worker exited with status {code}" + (f": {tail[0]}" if tail else "")
    return DecomposeOutcome(key, seconds=elapsed, failure=failure)


def _kill(run: _Running, limits: Limits) -> DecomposeOutcome:
    run.process.kill()
    run.process.wait()
    reason = (
        f"CoACD was still running after {limits.wall:g} s of wall-clock time, within its "
        f"{limits.cpu:g} CPU s budget (hung, or the machine is overloaded), and was stopped"
    )
    seconds = time.perf_counter() - run.started
    return DecomposeOutcome(run.job.key, seconds=seconds, failure=reason, stopped=Stop.WALL)


def decompose_all(
    jobs: list[DecomposeJob],
    *,
    workers: int | None = None,
    limits: Limits | None = None,
    on_done: Callable[[DecomposeOutcome], None] | None = None,
) -> dict[str, DecomposeOutcome]:
    """Decompose every job, at most `workers` at a time, each in its own process.

    Args:
        jobs: meshes to decompose.
        workers: processes at once (default: all cores); each gets cores // workers OpenMP
            threads, so a single worker still uses the whole machine.
        limits: each mesh's CPU budget and wall-clock backstop (default: DEFAULT_CPU_LIMIT).
        on_done: called in this process as each job finishes (progress display).

    Returns:
        One outcome per job key. Never raises for a worker that fails.
    """
    if not jobs:
        return {}
    limits = limits or Limits.for_cpu(DEFAULT_CPU_LIMIT)
    workers = max(1, min(workers or default_jobs(), len(jobs)))
    threads = max(1, default_jobs() // workers)
    pending, running, done = deque(enumerate(jobs)), [], {}
    with tempfile.TemporaryDirectory(prefix="twin-coacd-") as tmp:
        try:
            while pending or running:
                while pending and len(running) < workers:
                    index, job = pending.popleft()
                    running.append(_start(job, index, Path(tmp), threads, limits.cpu))
                time.sleep(POLL_S)
                for run in list(running):
                    outcome = _check(run, limits)
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


def _check(run: _Running, limits: Limits) -> DecomposeOutcome | None:
    """The outcome of a worker that has finished or overrun, else None (still working)."""
    if run.process.poll() is not None:
        return _collect(run, limits)
    if time.perf_counter() - run.started > limits.wall:
        return _kill(run, limits)
    return None
