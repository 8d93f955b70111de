"""MuJoCo's sensor history rings, which the world keeps in step with its clock.

A sensor with `nsample` keeps its last samples in `MjData.history` (MuJoCo 4.0, found by reading
it back): [last tick, cursor, times[n], values[n×dim]], the newest sample at `cursor`; entries
not yet written carry times at or before the start. With an `interval`, MuJoCo computes the
sensor at the first step where last tick + period <= time, then adds the period to the tick.
The world moves the rings with its clock (a time-only reset) and keeps each tick just before
its grid point (`align_sensor_ticks`); `twin_cli.sensors.history` reads the samples through
`ring_parts`. The layout lives here only.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import mujoco
    import numpy as np

TICK, CURSOR, TIMES = 0, 1, 2  # offsets in a sensor's ring; values follow the n times
TICK_LEAD = 1e-3  # of a step: an interval sensor's tick lead when its period is not whole steps


def ring_parts(
    history: np.ndarray, address: int, n: int, dim: int
) -> tuple[np.ndarray, np.ndarray]:
    """Views of one sensor's ring at `address` in `history`: its n times and n×dim values."""
    times = history[address + TIMES : address + TIMES + n]
    values = history[address + TIMES + n : address + TIMES + n + n * dim].reshape(n, dim)
    return times, values


def shift_sensor_history(model: mujoco.MjModel, data: mujoco.MjData, shift: float) -> None:
    """Moves the samples MuJoCo keeps for sensors with a history (an IMU's) by `shift` [s] with
    the clock, so that a time-only reset does not leave their last tick in the future: MuJoCo
    would compute them again only once sim time passed it."""
    ring = data.history
    for sensor in range(model.nsensor):
        n = int(model.sensor_history[sensor][0])
        if n > 0:
            address = int(model.sensor_historyadr[sensor])
            ring[address + TICK] += shift
            ring[address + TIMES : address + TIMES + n] += shift


def align_sensor_ticks(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Puts each interval sensor's last tick (ring slot 0) just before its grid point.

    MuJoCo computes such a sensor at the first step where last tick + period <= time, then adds
    the period to the tick. Sim time and the tick are sums of different floats (0.001 s and
    0.005 s), so a tick exactly on a step time lost that comparison to rounding now and then:
    the sample came one step late (2.001 s), and stayed late. A lead of half a step (when the
    period is a whole number of steps; else TICK_LEAD of a step, so a grid point between steps
    still goes to the first step after it) makes the comparison robust and keeps the k·period
    grid. A tick more than a period behind the clock (a sensor spawned after t = 0, whose tick
    MuJoCo starts at -period, or a clock moved by a reset) is brought to the clock: MuJoCo
    would otherwise sample it at every step until the tick caught up. Idempotent: every new
    model, timestep change and time-only reset calls it.
    """
    ring, step, now = data.history, float(model.opt.timestep), float(data.time)
    for sensor in range(model.nsensor):
        period, phase = (float(v) for v in model.sensor_interval[sensor])
        if int(model.sensor_history[sensor][0]) <= 0 or period <= 0.0:
            continue
        steps = period / step
        whole = abs(steps - round(steps)) < 1e-9 * max(1.0, steps)
        lead = min(0.5 * step, 0.25 * period) if whole else TICK_LEAD * min(step, period)
        address = int(model.sensor_historyadr[sensor])
        ticks = round((float(ring[address + TICK]) - phase) / period)
        if phase + (ticks + 2) * period <= now:  # behind: the next sample is the next grid point
            ticks = math.ceil((now - phase) / period - 1e-9) - 1
        ring[address + TICK] = phase + ticks * period - lead
