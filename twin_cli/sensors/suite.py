"""All sensors of one entity, read from a running world at their own update rates.

`SensorSuite.read` holds the world's lock once, for copies only: the `sensordata` of the due
sensors MuJoCo computes at every step (IMU, force/torque: see `imu`), and, only if some other
asked-for sensor is due (lidar, contact, camera), the world's state, which it evaluates outside
the lock on scratch data; sensors not due return their last reading. A sensor of rate r [Hz]
is due once per period 1/r of sim time, aligned to multiples of the period as Gazebo's sensor
manager updates them (rate 0: every physics step); a clock that went back (reset) makes every
sensor due. Readers therefore cost the loop a few copies per request, never a step of Python.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from converters.description.sensors import SensorSpec
from twin_cli.errors import InvalidRequestError, PartNotFoundError
from twin_cli.sensors.noise import sensor_rng
from twin_cli.sensors.readings import Reading
from twin_cli.sensors.registry import is_kinematic, sensor_class
from twin_cli.sensors.snapshot import STATE, Evaluator, Snapshot, take

if TYPE_CHECKING:
    from twin_cli.world.engine import World
    from twin_cli.world.entities import Entity

DUE_TOLERANCE = 1e-9  # [s] sim time accumulates rounding (0.2 != 200 * 0.001)


@dataclass(frozen=True)
class Pending:
    """What `SensorSuite.capture` copied under the lock, for `complete` to build readings from.

    Attributes:
        time: sim time [s]; wanted: the sensors asked for (due or not).
        native: (sample time [s], values) of the due sensors MuJoCo computes (IMU, F/T).
        rest: the other due sensors, read from `snapshot` (None when there are none).
        batches: (times, values k×n) of sensors whose kept samples were asked for (`since`).
    """

    time: float
    wanted: list[str]
    native: dict[str, tuple[float, np.ndarray]]
    rest: list[str]
    snapshot: Snapshot | None
    batches: dict[str, tuple[np.ndarray, np.ndarray]]


def period_slot(time: float, rate: float, timestep: float) -> int:
    """Which update period sim `time` [s] falls in for a sensor of `rate` [Hz] (0: per step)."""
    period = 1.0 / rate if rate > 0 else timestep
    return math.floor((time + DUE_TOLERANCE) / period)


class SensorSuite:
    """The sensors of entity `entity` in `world`, with reproducible noise (`seed`)."""

    def __init__(self, world: World, entity: str, *, seed: int = 0) -> None:
        """Raises: EntityNotFoundError: the world has no entity `entity`."""
        self.world = world
        self.entity = entity
        self.seed = seed
        self._evaluator = Evaluator()
        self._build(take(world, entity).entity)

    def _build(self, record: Entity) -> None:
        self._record = record
        self._model: mujoco.MjModel | None = None
        self.specs: dict[str, SensorSpec] = {s.name: s for s in record.sensors}
        self._sensors = {
            name: sensor_class(type(spec))(spec, self.entity, sensor_rng(self.seed, name))
            for name, spec in self.specs.items()
        }
        self._readings: dict[str, Reading] = {}
        self._slots: dict[str, int] = {}
        self._sampled: dict[str, float] = {}  # sensor with a history → time of its last sample

    @property
    def names(self) -> list[str]:
        return list(self.specs)

    def read(self, names: Sequence[str] | None = None) -> dict[str, Reading]:
        """The latest reading of each sensor in `names` (default: all), refreshed when due.

        Raises:
            EntityNotFoundError: the entity was deleted.
            PartNotFoundError: a name that is not one of the entity's sensors (lists them).
            InvalidRequestError: a due camera cannot render here (no offscreen GL).
        """
        with self.world.lock:  # held for a few µs: copies, no physics
            pending = self.capture(names)
        try:
            self.complete(pending)
        except Exception:  # nothing of this request was served: due again at the next read
            for name in [*pending.native, *pending.rest]:
                self._slots.pop(name, None)
                self._sampled.pop(name, None)
            raise
        return {n: self._readings[n] for n in pending.wanted}

    def capture(
        self, names: Sequence[str] | None = None, since: dict[str, float] | None = None
    ) -> Pending:
        """Copies what the due sensors among `names` need; call with the world's lock held.

        Their update periods count as served from here, so a recorder that completes the
        readings in another thread never captures one period twice. Sensors in `since` (name
        → sim time [s]; only those in `with_history`) give every sample MuJoCo kept after that
        time instead, due or not.

        Raises: as `read`, without the camera's error (that comes from `complete`).
        """
        time, model, record = float(self.world.data.time), self.world.model, self._entity()
        if record is not self._record:  # deleted and spawned again, or loaded
            self._build(record)
        wanted = list(self.specs) if names is None else list(names)
        for name in wanted:
            if name not in self.specs:
                raise PartNotFoundError(self.entity, "sensor", name, list(self.specs))
        timestep = model.opt.timestep
        if model is not self._model:
            self._bind(model)
        batches = {}
        for name, after in (since or {}).items():
            times, rows = self._sensors[name].samples_since(self.world.data, after)
            if len(times):
                batches[name] = (times, rows)
        kept = since or {}
        native, due = {}, []
        for name in wanted:
            if name in kept:
                continue
            sample = self._newest(name)
            if sample is not None:  # a new sample, else the reading of the last one stands
                if sample[0] != self._sampled.get(name):
                    self._sampled[name], native[name] = sample[0], sample
            elif self._due(name, time, timestep):
                due.append(name)
        for name in due:
            self._slots[name] = period_slot(time, self.specs[name].update_rate, timestep)
        native.update({n: self._capture(n, time) for n in due})
        rest = [n for n in due if native[n] is None]
        snapshot = self._snapshot(time, model, record) if rest else None
        native = {n: v for n, v in native.items() if v is not None}
        return Pending(time, wanted, native, rest, snapshot, batches)

    def with_history(self) -> list[str]:
        """The sensors whose past samples MuJoCo keeps (lock held): `capture(since=...)`."""
        if self.world.model is not self._model:
            self._bind(self.world.model)
        return [n for n, s in self._sensors.items() if getattr(s, "history", None) is not None]

    def complete(
        self, pending: Pending, errors: dict[str, Exception] | None = None
    ) -> list[Reading]:
        """Builds the readings `pending` captured (outside the lock).

        Args:
            errors: if given, a sensor that cannot be read here (a camera without offscreen GL)
                is left out and its error put there; else the error is raised.
        """
        fresh = {}
        for name, (time, values) in pending.native.items():
            fresh[name] = self._sensors[name].reading(values, time)
        if pending.snapshot is not None:
            fresh.update(self._refresh(pending.rest, pending.snapshot, errors))
        self._readings.update(fresh)
        out = list(fresh.values())
        for name, (times, rows) in pending.batches.items():
            sensor = self._sensors[name]  # the noise of all rows drawn at once
            batch = [
                sensor.reading(v, t, noisy=False)
                for t, v in zip(times.tolist(), sensor.noisy_batch(rows), strict=True)
            ]
            self._readings[name] = batch[-1]
            out += batch
        return out

    def _entity(self) -> Entity:
        """The entity's record (the world's; read-only).

        Raises:
            EntityNotFoundError: the entity is gone.
        """
        return self.world.entity(self.entity)

    def _bind(self, model: mujoco.MjModel) -> None:
        for sensor in self._sensors.values():
            sensor.bind(model)
        self._model = model

    def _newest(self, name: str) -> tuple[float, np.ndarray] | None:
        """The newest sample MuJoCo kept of a sensor with a history (None: none, or no sample
        yet). Such a sensor is read whenever a new sample exists: MuJoCo computes the sample of
        time t in the step that starts at t, so a period-based rule would serve it a period late.
        """
        sensor = self._sensors[name]
        if getattr(sensor, "history", None) is None:
            return None
        return sensor.latest(self.world.data)

    def _capture(self, name: str, time: float) -> tuple[float, np.ndarray] | None:
        """The last step's values of a sensor MuJoCo computes (F/T, an IMU without history),
        stamped `time`, else None."""
        capture = getattr(self._sensors[name], "capture", None)
        values = None if capture is None else capture(self.world.data)
        return None if values is None else (time, values)

    def _snapshot(self, time: float, model: mujoco.MjModel, record: Entity) -> Snapshot:
        state = np.empty(mujoco.mj_stateSize(model, STATE))
        mujoco.mj_getState(model, self.world.data, state, STATE)
        return Snapshot(time, model, state, record)

    def _due(self, name: str, time: float, timestep: float) -> bool:
        slot = period_slot(time, self.specs[name].update_rate, timestep)
        return slot != self._slots.get(name)

    def forget(self) -> None:
        """Makes every sensor due again (as after a reset); for benchmarks that replay a window."""
        self._slots.clear()
        self._sampled.clear()

    def _refresh(
        self, due: list[str], snapshot: Snapshot, errors: dict[str, Exception] | None
    ) -> dict[str, Reading]:
        # Rays and cameras need poses only (mj_kinematics, a few µs); the others need the
        # forward dynamics of the whole world (measured: ~30 µs with a humanoid in it).
        dynamics = any(not is_kinematic(self.specs[n]) for n in due)
        data = self._evaluator.evaluate(snapshot, dynamics=dynamics)
        model, out = snapshot.model, {}
        for name in due:
            try:
                out[name] = self._sensors[name].read(model, data, snapshot.time)
            except InvalidRequestError as exc:
                if errors is None:
                    self._slots.pop(name, None)  # not served: due again at the next read
                    raise
                errors[name] = exc
        return out


def describe_sensors(specs: Sequence[SensorSpec]) -> list[dict[str, Any]]:
    """One JSON-ready line per sensor: name, type, link, rate, topic, frame."""
    return [
        {
            "name": s.name,
            "type": s.type,
            "link": s.link,
            "update_rate": s.update_rate,
            "topic": s.topic,
            "frame_id": s.frame_id,
            "pose": list(s.pose),
        }
        for s in specs
    ]
