"""Past samples of MuJoCo's own sensors, kept by MuJoCo in a ring per sensor (`nsample`).

The converter gives an IMU's MuJoCo sensors its update period as `interval` and a history of
`converters.description.sensors.HISTORY_SAMPLES` samples, so MuJoCo computes them only when due
and remembers the last ones with their times, in C. A recorder then reads every sample of a
200 Hz IMU in one look every few dozen periods, instead of stopping the stepping at each period
(each stop costs the loop about as much as a physics step). The ring's layout is the world's
business (`twin_cli.world.sensor_rings`, which also keeps the rings in step with the clock).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from converters.description.sensors import HISTORY_SAMPLES
from twin_cli.world.sensor_rings import CURSOR, ring_parts

if TYPE_CHECKING:
    import mujoco

__all__ = ["HISTORY_SAMPLES", "SensorHistory"]


class SensorHistory:
    """The rings of some MuJoCo sensors that make up one twin sensor (same `nsample`)."""

    def __init__(self, model: mujoco.MjModel, sensors: list[int]) -> None:
        self.n = int(model.sensor_history[sensors[0]][0])
        self.parts = [(int(model.sensor_historyadr[s]), int(model.sensor_dim[s])) for s in sensors]
        self.width = sum(dim for _, dim in self.parts)

    @classmethod
    def of(cls, model: mujoco.MjModel, sensors: list[int]) -> SensorHistory | None:
        """The history of `sensors`, or None when one keeps none (a model built before)."""
        counts = {int(model.sensor_history[s][0]) for s in sensors}
        return cls(model, sensors) if sensors and len(counts) == 1 and min(counts) > 0 else None

    def since(self, data: mujoco.MjData, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Sample times [s] after `time` and not after now (samples from before a reset of the
        clock are not), oldest first, and their values (k × width).

        The parts of one twin sensor share their interval, so they are written in the same
        steps and their rings stay in step: one cursor orders them all."""
        ring, n = data.history, self.n
        first = self.parts[0][0]
        times, _ = ring_parts(ring, first, n, self.parts[0][1])
        new = np.flatnonzero((times > time + 1e-12) & (times <= data.time + 1e-12))
        cursor = int(ring[first + CURSOR])
        slots = new[np.argsort((new - cursor - 1) % n)]  # oldest first
        rows = np.empty((slots.size, self.width))
        column = 0
        for address, dim in self.parts:
            _, values = ring_parts(ring, address, n, dim)
            rows[:, column : column + dim] = values[slots]
            column += dim
        return times[slots], rows

    def latest(self, data: mujoco.MjData) -> tuple[float, np.ndarray]:
        """The newest sample's time [s] and values (width); it may date from before a reset of
        the clock (a time after now)."""
        ring, out, column = data.history, np.empty(self.width), 0
        time = 0.0
        for address, dim in self.parts:
            cursor = int(ring[address + CURSOR])
            times, values = ring_parts(ring, address, self.n, dim)
            time = float(times[cursor])
            out[column : column + dim] = values[cursor]
            column += dim
        return time, out
