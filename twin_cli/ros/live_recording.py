"""The bridge's sampling: a bag recording whose encoder is the publisher process.

The stepping thread's share per sample is a bag recording's (state copied into shared memory,
a few µs); the publisher process (`publisher`) builds and publishes the messages. Two things a
live view needs that a bag does not:
- sensors are thinned as the samples are: at most `max_wall_rate` × rate / RATE captures of a
  sensor per wall second, and of an IMU's kept samples the newest as many, so ray casting and
  building readings in the server never grow with the world's speed;
- a world that does not step (paused) is sampled every HEARTBEAT_S, so a late subscriber sees
  it and a spawn on a paused world appears;
- a world faster than the publisher's `max_wall_rate` is observed at a whole fraction of the
  rate (`stride`: every k-th sample of the 100 Hz grid, k the most that still brings
  `max_wall_rate` samples a wall second), not at the rate with most samples skipped: each
  observer call splits the loop's `mj_step` batch and runs Python between steps, and at the
  full rate an unthrottled humanoid (~15x real time, 1,500 calls a wall second for the state
  and as many for its sensors) spent ~6 % of its loop on the calls alone. The publisher's
  token bucket still takes the newest of what comes.
"""

from __future__ import annotations

import math
import sys
import threading
import time
from typing import TYPE_CHECKING

from twin_cli.record.bag_recording import BagRecording
from twin_cli.record.recorder import HEARTBEAT_S
from twin_cli.ros import publisher

SPEED_CHECK_S = 0.5  # [s] wall between measurements of the world's speed (sim s per wall s)

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
        self.stride = 1  # samples of the rate's grid per one taken (see `stride`)
        self._mark: tuple[float, float] | None = None  # (wall, sim) [s] at the last check
        self._beat = threading.Thread(target=self._heartbeat, name="twin-ros-beat", daemon=True)

    def start(self) -> RosRecording:
        super().start()
        self._beat.start()
        return self

    def retarget(self, world: World) -> None:
        self._mark = None  # the new world's clock is not the old one's
        super().retarget(world)

    def _encoder_command(self, fds: tuple[int, int]) -> list[str]:
        args = publisher.command(fds, self.scope, self.max_wall_rate)
        return [sys.executable, "-m", "twin_cli.ros.publisher", *args]

    def _capture(self) -> None:
        self._last_capture = now = time.monotonic()
        super()._capture()
        if self._mark is None or now - self._mark[0] >= SPEED_CHECK_S:
            self._check_speed(now)

    def _observer_rate(self, rate: float) -> float:
        return rate / self.stride

    def _check_speed(self, wall: float) -> None:
        """Measures the world's speed since the last check and observes it at the stride that
        speed calls for (stepping or heartbeat thread, lock held)."""
        sim = float(self._world.data.time)
        if self._mark is not None:
            speed = (sim - self._mark[1]) / max(wall - self._mark[0], 1e-9)
            wanted = stride(speed, self.rate, self.max_wall_rate)
            if wanted != self.stride:
                self._restride(wanted)
        self._mark = (wall, sim)

    def _restride(self, new: int) -> None:
        """Registers the state and sensor observers again at 1/`new` of their rates, from now
        (so their grids meet again as at the start)."""
        self.stride = new
        world = self._world
        if self._handle is not None:
            world.remove_observer(self._handle)
            self._handle = world.add_observer(self._capture, self._observer_rate(self.rate))
        if self._sensor_handles:
            for handle in self._sensor_handles:
                self._sensor_world.remove_observer(handle)
            self._sensor_handles = self._observe_sensors(self._sensor_world, self._sensor_rates)

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


def stride(speed: float, rate: float, max_wall_rate: float) -> int:
    """Samples of a `rate` [Hz] grid per one taken when the world runs at `speed` (sim s per wall
    s): the most that still leaves `max_wall_rate` [1/s] a wall second, at least 1 (a world no
    faster than max_wall_rate / rate, paused or gone back, loses none here)."""
    if not math.isfinite(speed) or speed <= 0.0:
        return 1
    return max(1, math.floor(speed * rate / max_wall_rate))
