"""The CoACD worker process: `python -m converters.collision.worker JOB.npz RESULT.npz`.

Reads one mesh, CoACD's keyword arguments and a CPU budget from JOB, writes the convex parts
and the CPU time CoACD took to RESULT, and exits 0. A Python error exits 3 with the message on
stderr; an abort inside CoACD simply kills this process, which is the point of running it here
rather than in twin. The budget is enforced by the kernel: `ITIMER_PROF` counts this process's
CPU time (every thread, user and system) from just before CoACD's call, and its signal,
CPU_SIGNAL, left at its default action, ends the process when the budget is spent (a Python
handler could not run while CoACD holds the interpreter).
"""

from __future__ import annotations

import json
import os
import signal
import sys
import time

import numpy as np

from converters.collision.cache import pack_parts

EXIT_ERROR = 3
# The signal that ends a worker over its CPU budget (None where the platform has no ITIMER_PROF;
# there only the parent's wall-clock backstop applies).
CPU_SIGNAL: int | None = getattr(signal, "SIGPROF", None)


def _inject(fault: str) -> None:
    """Misbehave as a test asked (decompose.FAULT_ENV): real deaths, real hangs."""
    if fault == "crash":
        os._exit(70)
    if fault == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    if fault == "abort":
        os.abort()
    if fault == "hang":
        time.sleep(3600)
    if fault == "error":
        raise RuntimeError("injected error")


def _arm_cpu_budget(seconds: float) -> None:
    """End this process once it has used `seconds` more CPU time [CPU s] (0: disarm)."""
    if CPU_SIGNAL is None:
        return
    signal.signal(CPU_SIGNAL, signal.SIG_DFL)  # an ignored SIGPROF is inherited through exec
    signal.setitimer(signal.ITIMER_PROF, seconds)


def run(job_path: str, result_path: str) -> None:
    """Decompose the mesh in `job_path` and write the parts to `result_path` (atomically).

    The worker ends with the process that started it: a conversion killed in its bounded child
    (a cancelled background decomposition, a world shutting down) leaves no CoACD running.
    """
    from converters.isolated.bounded_child import die_with_parent

    die_with_parent()
    with np.load(job_path, allow_pickle=False) as job:
        vertices = np.asarray(job["vertices"], np.float64)
        faces = np.asarray(job["faces"], np.int32)
        params = json.loads(str(job["params"]))
        fault = str(job["fault"])
        cpu_limit = float(job["cpu_limit"])
    _inject(fault)
    import coacd

    coacd.set_log_level("error")
    mesh = coacd.Mesh(vertices, faces)
    started = time.process_time()
    _arm_cpu_budget(cpu_limit)
    parts = coacd.run_coacd(mesh, **params)
    _arm_cpu_budget(0.0)  # disarm: writing the result is not CoACD's work
    cpu_seconds = time.process_time() - started
    arrays = {
        **pack_parts(parts),
        "count": np.array(len(parts)),
        "cpu_seconds": np.array(cpu_seconds),
    }
    tmp = f"{result_path}.part"
    with open(tmp, "wb") as stream:
        np.savez(stream, allow_pickle=False, **arrays)  # numbers only: no pickles
    os.replace(tmp, result_path)


def main() -> None:
    try:
        run(sys.argv[1], sys.argv[2])
    except Exception as exc:  # the parent reads this line and falls back to the hull
        sys.stderr.write(f"{type(exc).__name__}: {exc}\n")
        sys.exit(EXIT_ERROR)


if __name__ == "__main__":
    main()
