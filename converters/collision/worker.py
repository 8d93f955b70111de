"""The CoACD worker process: `python -m converters.collision.worker JOB.npz RESULT.npz`.

Reads one mesh and CoACD's keyword arguments from JOB, writes the convex parts to RESULT, and
exits 0. A Python error exits 3 with the message on stderr; an abort inside CoACD simply kills
this process, which is the point of running it here rather than in twin.
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


def run(job_path: str, result_path: str) -> None:
    """Decompose the mesh in `job_path` and write the parts to `result_path` (atomically)."""
    with np.load(job_path, allow_pickle=False) as job:
        vertices = np.asarray(job["vertices"], np.float64)
        faces = np.asarray(job["faces"], np.int32)
        params = json.loads(str(job["params"]))
        fault = str(job["fault"])
    _inject(fault)
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(vertices, faces), **params)
    arrays = {**pack_parts(parts), "count": np.array(len(parts))}
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
