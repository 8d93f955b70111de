"""A thread that builds a `SensorFeed`'s captures off the stepping thread, polled, not woken.

Waking another thread for every capture (a queue's put) costs the waker a futex call and, on a
VM, an inter-processor interrupt: measured 40-50 µs of the stepping thread's CPU per capture,
so a 200 Hz IMU alone took a third of an unthrottled humanoid loop. Here the stepping thread
only appends to a deque; the pump's thread looks every POLL_S, builds what is there (ray
casting, rendering, noise) and hands the readings to `deliver`. Nothing is dropped: past
MAX_BACKLOG captures the stepping thread waits for the pump, as it waits for a full recording
ring, and as gz-sim's rendering sensors hold the simulation back; that wait is `blocked_s`.
"""

from __future__ import annotations

import collections
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from twin_cli.record.sensor_feed import SensorFeed
from twin_cli.record.topics import Topic
from twin_cli.sensors import Reading

log = logging.getLogger("twin.record")
POLL_S = 0.01  # [s] between the pump's looks at its backlog
MAX_BACKLOG = 256  # captures waiting for the pump before the stepping thread waits
WAIT_S = 0.0005  # [s] the stepping thread's poll period while the backlog is full


class SensorPump:
    """Builds captures of sensor feeds in a thread and passes the readings to `deliver`."""

    def __init__(
        self, deliver: Callable[[list[tuple[Topic, Reading]]], None], name: str = "sensors"
    ) -> None:
        """Args: deliver: called in the pump's thread with each non-empty batch of readings;
        what it raises is logged and kept as `error` (the pump goes on)."""
        self._deliver = deliver
        self._backlog: collections.deque[tuple[SensorFeed, Any]] = collections.deque()
        self._closing = threading.Event()
        self._building = False  # the pump's thread is between taking a capture and delivering
        self._thread = threading.Thread(target=self._run, name=f"twin-{name}", daemon=True)
        self.blocked_s = 0.0  # [s] the stepping thread waited for room
        self.error: str | None = None

    def start(self) -> SensorPump:
        self._thread.start()
        return self

    def capture(self, feed: SensorFeed, rate: float | None = None) -> None:
        """Stepping thread, world lock held: copies the due sensors of `feed` into the backlog."""
        captured = feed.capture(rate)
        if not captured:
            return
        if len(self._backlog) >= MAX_BACKLOG:
            start = time.perf_counter()
            while len(self._backlog) >= MAX_BACKLOG and self._thread.is_alive():
                time.sleep(WAIT_S)
            self.blocked_s += time.perf_counter() - start
        self._backlog.append((feed, captured))

    def flush(self) -> None:
        """Waits until every capture so far is built and delivered (the thread must run)."""
        while (self._backlog or self._building) and self._thread.is_alive():
            time.sleep(WAIT_S)

    def close(self) -> None:
        """Builds and delivers what is still captured, then ends the thread."""
        self._closing.set()
        if self._thread.is_alive():
            self._thread.join()
        else:  # never started (a caller that steps the world itself): build them here
            self._drain()

    def _run(self) -> None:
        while not self._closing.wait(POLL_S):
            self._drain()
        self._drain()

    def _drain(self) -> None:
        while self._backlog:
            self._building = True
            feed, captured = self._backlog.popleft()
            try:
                readings = feed.build(captured)
                if readings:
                    self._deliver(readings)
            except Exception as exc:  # a failing sensor or sink: report it, keep the others
                log.exception("sensor readings failed")
                self.error = self.error or f"sensor readings: {type(exc).__name__}: {exc}"
            finally:
                self._building = False
            time.sleep(0)  # hand the GIL to the stepping thread between captures
