"""IMU: orientation, angular velocity and specific force at the sensor's site.

A real accelerometer measures the specific force f = a − g (its proof mass is held against
gravity), so an IMU lying still reads +9.81 m/s² up and one in free fall reads 0. MuJoCo's
`cacc` starts from the world body's acceleration −g (`mj_rnePostConstraint`), so its
`accelerometer` sensor (and `mj_objectAcceleration` of the site) is exactly a − g, including
the centripetal term of the site's offset from the body, in the site frame; so is its `gyro`.
The orientation is the site's orientation in the world (ENU, as gz-sim reports it).

The converter adds MuJoCo's `framequat`, `gyro` and `accelerometer` sensors on the site,
computed in C at the IMU's update period and kept with their times (`history`); a reading is
the newest kept sample (the state at its own sim time, as Gazebo's IMU reports its last update)
with noise added, and a recorder takes every kept sample in one look. A model without them (or
a world not stepped since it was built) is evaluated on a snapshot instead, with the same
functions MuJoCo uses.
"""

from __future__ import annotations

import mujoco
import numpy as np

from converters.description.sensors import ImuSpec
from twin_cli.sensors.frames import native_ids, native_slice, site_id
from twin_cli.sensors.history import SensorHistory
from twin_cli.sensors.noise import NoiseSampler
from twin_cli.sensors.readings import ImuReading
from twin_cli.sensors.registry import sensor_for

IDENTITY = (0.0, 0.0, 0.0, 1.0)  # x y z w: what an IMU without orientation reports


@sensor_for(ImuSpec)
class ImuSensor:
    """One `<sensor type="imu">` of an entity."""

    def __init__(self, spec: ImuSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.gyro_noise = NoiseSampler(spec.angular_velocity_noise, rng)
        self.accel_noise = NoiseSampler(spec.linear_acceleration_noise, rng)
        self.site = -1
        self.native: slice | None = None
        self._data: mujoco.MjData | None = None
        self._view = np.zeros(0)
        self.history: SensorHistory | None = None

    def bind(self, model: mujoco.MjModel) -> None:
        self.site = site_id(model, self.entity, self.spec.site)
        parts = self.spec.native_parts
        self.native = native_slice(model, self.entity, self.spec.site, parts)
        ids = native_ids(model, self.entity, self.spec.site, parts)
        self.history = SensorHistory.of(model, ids) if self.native is not None else None
        self._data = None

    def latest(self, data: mujoco.MjData) -> tuple[float, np.ndarray] | None:
        """The newest sample MuJoCo kept (its time [s] and `capture`'s values), None when
        there is no history or no sample yet; a copy."""
        if self.history is None:
            return None
        time, values = self.history.latest(data)
        fresh = values[:4] @ values[:4] > 0.0 and time <= data.time + 1e-12  # not pre-reset
        return (time, values) if fresh else None

    def samples_since(self, data: mujoco.MjData, time: float) -> tuple[np.ndarray, np.ndarray]:
        """Every kept sample after sim `time` [s]: times, oldest first, and values (k×10)."""
        assert self.history is not None
        times, rows = self.history.since(data, time)
        computed = np.einsum("ij,ij->i", rows[:, :4], rows[:, :4]) > 0.0
        return times[computed], rows[computed]

    def capture(self, data: mujoco.MjData) -> np.ndarray | None:
        """The last step's (quat w x y z, gyro, specific force) in `sensordata`: a copy; None
        when MuJoCo has not computed them (no native sensors, or not stepped since built)."""
        if self.native is None:
            return None
        if data is not self._data:  # a view per MjData: attribute access costs µs per call
            self._data, self._view = data, data.sensordata[self.native]
        values = self._view.copy()
        return values if values[:4] @ values[:4] > 0.0 else None

    def read(self, model: mujoco.MjModel, data: mujoco.MjData, time: float) -> ImuReading:
        """The reading of `data` (after forward dynamics and `mj_rnePostConstraint`)."""
        values = self.capture(data)
        return self.reading(values if values is not None else self.compute(model, data), time)

    def compute(self, model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
        """What the native sensors hold, computed from evaluated `data` (same 10 numbers)."""
        out = np.zeros(10)
        velocity, acceleration = np.zeros(6), np.zeros(6)
        site = mujoco.mjtObj.mjOBJ_SITE
        mujoco.mj_objectVelocity(model, data, site, self.site, velocity, 1)
        mujoco.mj_objectAcceleration(model, data, site, self.site, acceleration, 1)
        quat = out[:4]
        mujoco.mju_mat2Quat(quat, data.site_xmat[self.site])
        out[4:7], out[7:10] = velocity[:3], acceleration[3:]
        return out

    def noisy_batch(self, values: np.ndarray) -> np.ndarray:
        """Rows of `capture` values (N×10) with the tags' noise drawn for all rows at once."""
        out = values.copy()
        out[:, 4:7] = self.gyro_noise.apply(values[:, 4:7])
        out[:, 7:10] = self.accel_noise.apply(values[:, 7:10])
        return out

    def reading(self, values: np.ndarray, time: float, *, noisy: bool = True) -> ImuReading:
        """The reading of `values` (as `capture` returns them), with the tags' noise unless
        `noisy` is False (values from `noisy_batch`)."""
        w, x, y, z = values[:4].tolist()
        gyro, accel = values[4:7], values[7:10]
        if noisy:
            gyro, accel = self.gyro_noise.apply_one(gyro), self.accel_noise.apply_one(accel)
        gyro, accel = gyro.tolist(), accel.tolist()
        return ImuReading(
            self.spec.name,
            self.spec.type,
            time,
            self.spec.frame_id,
            (x, y, z, w) if self.spec.enable_orientation else IDENTITY,
            (gyro[0], gyro[1], gyro[2]),
            (accel[0], accel[1], accel[2]),
        )
