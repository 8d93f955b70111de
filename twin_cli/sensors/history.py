"""Past samples of MuJoCo's own sensors, kept by MuJoCo in a ring per sensor (`nsample`).

The converter gives an IMU's MuJoCo sensors its update period as `interval` and a history of
`converters.description.sensors.HISTORY_SAMPLES` samples, so MuJoCo computes them only when due
and remembers the last ones with their times, in C. A recorder then reads every sample of a
200 Hz IMU in one look every few dozen periods, instead of stopping the stepping at each period
(each stop costs the loop about as much as a physics step). Layout of one sensor's ring in
`MjData.history` (MuJoCo 4.0, found by reading it back): [last update time, cursor, times[n],
values[n×dim]], the newest sample at `cursor`; entries not yet written carry times at or
before the start.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from converters.description.sensors import HISTORY_SAMPLES

__all__ = ["HISTORY_SAMPLES", "SensorHistory"]


class SensorHistory:
    """The rings of some MuJoCo sensors that make up one twin sensor (same `nsample`)."""

    def __init__(self, model: Any, sensors: list[int]) -> None:
        self.n = int(model.sensor_history[sensors[0]][0])
        self.parts = [(int(model.sensor_historyadr[s]), int(model.sensor_dim[s])) for s in sensors]
        self.width = sum(dim for _, dim in self.parts)

    @classmethod
    def of(cls, model: Any, sensors: list[int]) -> SensorHistory | None:
        """The history of `sensors`, or None when one keeps none (a model built before)."""
        counts = {int(model.sensor_history[s][0]) for s in sensors}
        return cls(model, sensors) if sensors and len(counts) == 1 and min(counts) > 0 else None

    def since(self, data: Any, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Sample times [s] after `time` and not after now (samples from before a reset of the
        clock are not), oldest first, and their values (k × width).

        The parts of one twin sensor share their interval, so they are written in the same
        steps and their rings stay in step: one cursor orders them all."""
        ring, n = data.history, self.n
        first = self.parts[0][0]
        times = ring[first + 2 : first + 2 + n]
        new = np.flatnonzero((times > time + 1e-12) & (times <= data.time + 1e-12))
        cursor = int(ring[first + 1])
        slots = new[np.argsort((new - cursor - 1) % n)]  # oldest first
        rows = np.empty((slots.size, self.width))
        column = 0
        for address, dim in self.parts:
            values = ring[address + 2 + n : address + 2 + n + n * dim].reshape(n, dim)
            rows[:, column : column + dim] = values[slots]
            column += dim
        return times[slots], rows

    def latest(self, data: Any) -> tuple[float, np.ndarray]:
        """The newest sample's time [s] and values (width); it may date from before a reset of
        the clock (a time after now)."""
        ring, out, column = data.history, np.empty(self.width), 0
        time = 0.0
        for address, dim in self.parts:
            n, cursor = self.n, int(ring[address + 1])
            time = float(ring[address + 2 + cursor])
            start = address + 2 + n + cursor * dim
            out[column : column + dim] = ring[start : start + dim]
            column += dim
        return time, out
