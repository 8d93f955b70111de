"""IMU: orientation, angular velocity and specific force at the sensor's site.

A real accelerometer measures the specific force f = a − g (its proof mass is held against
gravity), so an IMU lying still reads +9.81 m/s² up and one in free fall reads 0. MuJoCo's
`cacc` starts from the world body's acceleration −g (`mj_rnePostConstraint`), so
`mj_objectAcceleration` of the site is exactly a − g, including the centripetal term of the
site's offset from the body; it is taken in the site frame (`flg_local`), as is the angular
velocity. The orientation is the site's orientation in the world (ENU, as gz-sim reports it).
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from converters.description.sensors import ImuSpec
from twin_cli.sensors.frames import site_id
from twin_cli.sensors.noise import NoiseSampler
from twin_cli.sensors.readings import ImuReading


class ImuSensor:
    """One `<sensor type="imu">` of an entity."""

    def __init__(self, spec: ImuSpec, entity: str, rng: np.random.Generator) -> None:
        self.spec = spec
        self.entity = entity
        self.gyro_noise = NoiseSampler(spec.angular_velocity_noise, rng)
        self.accel_noise = NoiseSampler(spec.linear_acceleration_noise, rng)
        self.site = -1

    def bind(self, model: Any) -> None:
        self.site = site_id(model, self.entity, self.spec.site)

    def read(self, model: Any, data: Any, time: float) -> ImuReading:
        """The reading of `data` (after forward dynamics and `mj_rnePostConstraint`)."""
        velocity = np.zeros(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_SITE, self.site, velocity, 1)
        acceleration = np.zeros(6)
        mujoco.mj_objectAcceleration(
            model, data, mujoco.mjtObj.mjOBJ_SITE, self.site, acceleration, 1
        )
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, data.site_xmat[self.site])
        w, x, y, z = quat.tolist()
        return ImuReading(
            self.spec.name,
            self.spec.type,
            time,
            self.spec.frame_id,
            (x, y, z, w) if self.spec.enable_orientation else (0.0, 0.0, 0.0, 1.0),
            _vec(self.gyro_noise.apply(velocity[:3])),
            _vec(self.accel_noise.apply(acceleration[3:])),
        )


def _vec(v: np.ndarray) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))
