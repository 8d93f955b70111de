"""The stepping thread: paces a World to the wall clock and meters its real-time factor.

Every decision (how many steps, when to wake, batch size, RTF) is a pure function from
`twin_cli.world.realtime`; this module only reads the clock, sleeps, and holds the world's lock
for one batch at a time, so requests interleave with stepping. `mj_step(m, d, nstep=N)` releases
the GIL, so other threads run while a batch steps.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

from twin_cli.world import realtime as rt
from twin_cli.world.running import advance

if TYPE_CHECKING:
    from twin_cli.world.state import WorldState

PAUSED_POLL_S = 0.05  # [s] how often a paused loop wakes to sample the meter
YIELD_POLL_S = 0.00005  # [s] sleep while a request waits for the lock
YIELD_MAX_S = 0.01  # [s] longest the loop defers to waiting requests after a batch
# [s] longest sleep between due steps: at a rate of 1e-4 Hz the next step is hours away, and a
# rate change or `stop` must still be seen at once (the API fuzz found the server deaf to both).
IDLE_POLL_S = 0.05


class WorldLock:
    """A re-entrant lock that counts the threads waiting for it.

    Python locks are not fair: a loop that releases and re-acquires at once can starve a waiting
    request. The loop asks `waiting` after each batch and steps aside while it is non-zero.
    Supports `with`, `acquire` and `release` like `threading.RLock`.
    """

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._count = threading.Lock()
        self._waiting = 0

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        with self._count:
            self._waiting += 1
        try:
            return self._lock.acquire(blocking, timeout)
        finally:
            with self._count:
                self._waiting -= 1

    def release(self) -> None:
        self._lock.release()

    def __enter__(self) -> WorldLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    @property
    def waiting(self) -> int:
        """Threads blocked in `acquire` right now."""
        return self._waiting


@dataclass(frozen=True)
class LoopFigures:
    """What the loop measured since it started or was last reset.

    Attributes:
        factor: gz-stats real-time factor; real_time: wall time [s] since start/reset;
        lateness: sync-point lateness of batches; dropped: steps skipped to avoid bursting.
    """

    factor: float
    real_time: float
    lateness: rt.Lateness
    dropped: int


class SteppingLoop:
    """Runs `running.advance` on a world's state in a daemon thread at its update rate."""

    def __init__(self, state: WorldState) -> None:
        self._state = state
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._origin = time.perf_counter()
        self._meter = rt.RtfMeter()
        self._lateness = rt.Lateness()
        self._dropped = 0
        self._epoch = 0

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def start(self) -> None:
        """Starts the thread (no-op when running)."""
        if self.running:
            return
        self._stop.clear()
        self.reset_clock()
        self._thread = threading.Thread(target=self._run, name="twin-world-loop", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stops the thread and waits for it."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        self._thread = None

    def reset_clock(self) -> None:
        """Restarts real time and the meter (world reset, rate change, resume)."""
        self._origin = time.perf_counter()
        self._meter = rt.RtfMeter()
        self._lateness = rt.Lateness()
        self._dropped = 0
        self._epoch += 1

    def reanchor(self) -> None:
        """Makes the pacer restart from now (rate changed, resumed) without clearing figures."""
        self._epoch += 1

    def figures(self) -> LoopFigures:
        real = time.perf_counter() - self._origin if self.running else 0.0
        return LoopFigures(rt.factor(self._meter), real, self._lateness, self._dropped)

    def _run(self) -> None:
        epoch, pacer, done, batch = -1, None, 0, 1
        while not self._stop.is_set():
            now = time.perf_counter()
            state = self._state
            rate, paused, sim = state.settings.rate, state.paused, float(state.data.time)
            self._meter = rt.observe_running(self._meter, now - self._origin, sim, paused)
            if paused:
                self._stop.wait(PAUSED_POLL_S)
                epoch = -1
                continue
            if epoch != self._epoch or pacer is None:
                epoch, done = self._epoch, 0
                pacer = rt.start_pacer(rate, now, done)
            n, pacer = rt.steps_due(pacer, now, done, batch)
            if n == 0:
                wait = rt.next_wake(pacer, done) - time.perf_counter()
                self._stop.wait(min(max(0.0, wait), IDLE_POLL_S))
                continue
            self._lateness = rt.record_lateness(
                self._lateness, now - rt.due_time(pacer, done + 1), pacer.period
            )
            self._dropped = pacer.dropped
            batch = self._run_batch(n)
            done += n
            self._step_aside()

    def _run_batch(self, n: int) -> int:
        """Steps n under the lock; returns the batch size for the next one."""
        with self._state.lock:
            start = time.perf_counter()
            advance(self._state, n)
            took = time.perf_counter() - start
        return rt.batch_limit(n, took)

    def _step_aside(self) -> None:
        lock = self._state.lock
        if not lock.waiting:
            return
        deadline = time.perf_counter() + YIELD_MAX_S
        while lock.waiting and time.perf_counter() < deadline:
            time.sleep(YIELD_POLL_S)
