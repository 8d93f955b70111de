"""Where sweep tasks run: a local process pool (`--jobs`) or a Ray cluster (`--ray`).

Both hand back `(task index, result)` pairs as tasks finish, so the caller can show progress
and still put results in task order: the order of completion never changes a report.
"""

from __future__ import annotations

import contextlib
import os
import socket
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from twin_cli.validate.sweep_errors import SweepError

ONE_THREAD = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
"""Environment of the pool's workers: one BLAS thread each. A worker already is one per core;
numpy's default of a BLAS thread per core oversubscribed 2 cores with 4 threads and made
`--jobs 2` slower than `--jobs 1` (24.4 s vs 15.1 s on 20 humanoid variants)."""

RAY_CONNECT_TIMEOUT_S = 3.0
"""[s] how long a named Ray address may take to accept a TCP connection before it counts as down
(Ray's own client retries for about a minute; a typo should fail at once)."""


class LocalPool:
    """A pool of `jobs` worker processes, started with `spawn` (no state forked from a caller
    that may hold threads or a MuJoCo world)."""

    def __init__(self, jobs: int) -> None:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        self.name = f"local pool, {jobs} process{'es' if jobs > 1 else ''}"
        self._pool = ProcessPoolExecutor(jobs, mp_context=multiprocessing.get_context("spawn"))

    def imap(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[tuple[int, Any]]:
        from concurrent.futures import as_completed

        with _environment(ONE_THREAD):  # workers start on the first submits
            futures = {self._pool.submit(fn, task): i for i, task in enumerate(tasks)}
        for future in as_completed(futures):
            yield futures[future], future.result()

    def close(self) -> None:
        self._pool.shutdown(cancel_futures=True)


class RayCluster:
    """Tasks as Ray remote functions on the cluster at `address` ("auto": the running one)."""

    def __init__(self, address: str) -> None:
        import ray

        self._ray = ray
        self._owned = False
        if not ray.is_initialized():
            if address != "auto":
                _probe(address)
            try:
                ray.init(address=address, logging_level="ERROR", log_to_driver=False)
            except (ConnectionError, RuntimeError, ValueError) as exc:
                raise SweepError(
                    f"--ray {address}",
                    f"no Ray cluster answers ({str(exc).splitlines()[0]})",
                    "start one with `ray start --head`, or give its address HOST:PORT",
                ) from exc
            self._owned = True
        cpus = int(ray.cluster_resources().get("CPU", 0))
        self.name = f"Ray cluster, {cpus} CPUs"

    def imap(self, fn: Callable[[Any], Any], tasks: Iterable[Any]) -> Iterator[tuple[int, Any]]:
        remote = self._ray.remote(num_cpus=1)(fn)
        refs = {remote.remote(task): i for i, task in enumerate(tasks)}
        pending = list(refs)
        while pending:
            ready, pending = self._ray.wait(pending, num_returns=1)
            for ref in ready:
                yield refs[ref], self._ray.get(ref)

    def close(self) -> None:
        if self._owned:
            self._ray.shutdown()


@contextlib.contextmanager
def _environment(values: dict[str, str]) -> Iterator[None]:
    """`values` in os.environ for the block (where the user set one, theirs is kept)."""
    added = {k: v for k, v in values.items() if k not in os.environ}
    os.environ.update(added)
    try:
        yield
    finally:
        for key in added:
            os.environ.pop(key, None)


def _probe(address: str) -> None:
    """Fail fast when HOST:PORT (or ray://HOST:PORT) does not accept a TCP connection.

    Raises:
        SweepError: malformed address, or nothing listening within RAY_CONNECT_TIMEOUT_S.
    """
    given = f"--ray {address}"
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        raise SweepError(given, "not HOST:PORT", "give auto or the head node's HOST:PORT")
    try:
        with socket.create_connection((host, int(port)), timeout=RAY_CONNECT_TIMEOUT_S):
            pass
    except OSError as exc:
        raise SweepError(
            given,
            f"no Ray cluster answers ({exc.strerror or exc})",
            "start one with `ray start --head`, or check the head node's HOST:PORT",
        ) from exc


@contextlib.contextmanager
def open_executor(*, jobs: int | None = None, ray: str | None = None) -> Iterator[Any]:
    """A Ray cluster when `ray` is given, else a local pool of `jobs` (default: every core).

    Raises:
        SweepError: jobs < 1, Ray not installed, or no cluster at the address.
    """
    if jobs is not None and jobs < 1:
        raise SweepError(f"--jobs {jobs}", "needs at least one worker", "give --jobs 1 or more")
    if ray is not None:
        try:
            import ray as _ray  # noqa: F401
        except ImportError as exc:
            raise SweepError(
                f"--ray {ray}", "Ray is not installed", "pip install 'twin[ray]'"
            ) from exc
        executor: Any = RayCluster(ray)
    else:
        executor = LocalPool(jobs or os.cpu_count() or 1)
    try:
        yield executor
    finally:
        executor.close()
