"""The bridge's sampling: a bag recording whose encoder is the publisher process.

The stepping thread's share per sample is a bag recording's (state copied into shared memory,
a few µs); the publisher process (`publisher`) builds and publishes the messages. Two things a
live view needs that a bag does not:
- sensors are thinned as the samples are: at most `max_wall_rate` × rate / RATE captures of a
  sensor per wall second, and of an IMU's kept samples the newest as many, so ray casting and
  building readings in the server never grow with the world's speed;
- a world that does not step (paused) is sampled every HEARTBEAT_S, so a late subscriber sees
  it and a spawn on a paused world appears.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import TYPE_CHECKING

from twin_cli.record.bag_recording import BagRecording
from twin_cli.record.recorder import HEARTBEAT_S
from twin_cli.ros import publisher

if TYPE_CHECKING:
    from twin_cli.ros.scope import Scope
    from twin_cli.world.engine import World


class RosRecording(BagRecording):
    """Samples `world` at `rate` [Hz] of sim time for the publisher process in `scope`."""

    def __init__(
        self,
        world: World,
        scope: Scope,
        *,
        rate: float,
        max_wall_rate: float,
        frame_prefix: str | None = None,
    ) -> None:
        super().__init__(world, None, rate=rate, frame_prefix=frame_prefix)
        self.scope = scope
        self.max_wall_rate = max_wall_rate
        self._sensor_slots: dict[float, float] = {}  # sensor rate → next wall time it may go
        self._last_capture = time.monotonic()
        self._beat = threading.Thread(target=self._heartbeat, name="twin-ros-beat", daemon=True)

    def start(self) -> RosRecording:
        super().start()
        self._beat.start()
        return self

    def _encoder_command(self, fds: tuple[int, int]) -> list[str]:
        args = publisher.command(fds, self.scope, self.max_wall_rate)
        return [sys.executable, "-m", "twin_cli.ros.publisher", *args]

    def _capture(self) -> None:
        self._last_capture = time.monotonic()
        super()._capture()

    def _follow_sensors(self, world: World) -> None:
        self._feed.wall_share = self.max_wall_rate / self.rate  # an IMU's kept samples too
        super()._follow_sensors(world)

    def _capture_sensors(self, rate: float | None = None) -> None:
        if rate is not None:  # thinned alike: at most max_wall_rate × rate / self.rate a second
            now = time.monotonic()
            if now < self._sensor_slots.get(rate, 0.0):
                return
            self._sensor_slots[rate] = now + self.rate / (rate * self.max_wall_rate)
        super()._capture_sensors(rate)

    def _heartbeat(self) -> None:
        """Samples a world that has not been sampled for HEARTBEAT_S (paused, or just loaded)."""
        while not self._done.wait(HEARTBEAT_S / 2):
            if self._handle is not None and time.monotonic() - self._last_capture >= HEARTBEAT_S:
                with self._world.lock:
                    if time.monotonic() - self._last_capture >= HEARTBEAT_S:
                        self._capture()
