"""Every reading of a running world's sensors, at each sensor's update times (for recorders).

`SensorSuite.read` serves the latest reading on request; a recorder wants every reading, at
the sensor's rate in sim time, however fast the world runs. A `SensorStream` registers one
world observer per distinct rate (`World.add_observer`: the stepping code stops at the due
steps, no Python per physics step). The observer only copies, with the lock held: the
`sensordata` slice of an IMU or F/T sensor (MuJoCo computes them every step), or the world's
state for the others (lidar, contact, camera). `drain` then builds the readings outside the
lock, with each sensor's noise drawn for the whole batch at once, in time order.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from typing import Any

import mujoco
import numpy as np

from twin_cli.errors import PartNotFoundError
from twin_cli.sensors.readings import Reading
from twin_cli.sensors.snapshot import STATE, Snapshot
from twin_cli.sensors.suite import KINEMATIC


class SensorStream:
    """Captures sensors `names` of `suite` (default: all) at their rates until `close`."""

    def __init__(self, suite: Any, names: Sequence[str] | None = None) -> None:
        """Raises: PartNotFoundError: a name that is not one of the entity's sensors."""
        self.suite = suite
        self.names = list(suite.specs) if names is None else list(names)
        for name in self.names:
            if name not in suite.specs:
                raise PartNotFoundError(suite.entity, "sensor", name, list(suite.specs))
        self._record = suite._record
        # (name, sim time, sensordata values or world state, model, whether it is a state)
        self._captured: list[tuple[str, float, np.ndarray, Any, bool]] = []
        world = suite.world
        by_rate: dict[float, list[str]] = defaultdict(list)
        with world.lock:
            step_rate = 1.0 / float(world.model.opt.timestep)
        for name in self.names:
            rate = suite.specs[name].update_rate
            by_rate[rate if rate > 0 else step_rate].append(name)
        self._handles = [
            world.add_observer(lambda group=group: self._capture(group), rate)
            for rate, group in by_rate.items()
        ]

    def _capture(self, names: list[str]) -> None:
        """Observer callback (world lock held): copies what the due readings need."""
        world, suite = self.suite.world, self.suite
        if world._entities.get(suite.entity) is not self._record:
            return  # the entity was deleted (or replaced): nothing of it to read
        model, data = world.model, world.data
        if model is not suite._model:
            suite._bind(model)
        time = float(data.time)
        state = None
        for name in names:
            capture = getattr(suite._sensors[name], "capture", None)
            values = None if capture is None else capture(data)
            if values is None and state is None:
                state = np.empty(mujoco.mj_stateSize(model, STATE))
                mujoco.mj_getState(model, data, state, STATE)
            if values is None:
                self._captured.append((name, time, state, model, True))
            else:
                self._captured.append((name, time, values, model, False))

    def drain(self) -> list[Reading]:
        """The readings captured since the last drain, in time order (sensors in name order)."""
        with self.suite.world.lock:
            captured, self._captured = self._captured, []
        native: dict[str, list[tuple[float, np.ndarray]]] = defaultdict(list)
        out: list[Reading] = []
        for name, time, values, model, is_state in captured:
            if is_state:
                out.append(self._from_state(name, time, values, model))
            else:
                native[name].append((time, values))
        for name, rows in native.items():
            out.extend(_batch(self.suite._sensors[name], rows))
        out.sort(key=lambda r: (r.time, self.names.index(r.sensor)))
        return out

    def _from_state(self, name: str, time: float, state: np.ndarray, model: Any) -> Reading:
        snapshot = Snapshot(time, model, state, self._record)
        kinematic = isinstance(self.suite.specs[name], KINEMATIC)  # poses only: rays, cameras
        data = self.suite._evaluator.evaluate(snapshot, dynamics=not kinematic)
        return self.suite._sensors[name].read(model, data, time)

    def close(self) -> None:
        """Stops capturing (the readings not drained yet are kept)."""
        for handle in self._handles:
            self.suite.world.remove_observer(handle)
        self._handles = []


def _batch(sensor: Any, rows: list[tuple[float, np.ndarray]]) -> list[Reading]:
    """Readings of one natively computed sensor, its noise drawn for all rows at once."""
    values = np.stack([v for _, v in rows])
    batch = getattr(sensor, "noisy_batch", None)
    if batch is not None:
        values = batch(values)
    return [sensor.reading(v, t, noisy=False) for (t, _), v in zip(rows, values, strict=True)]
