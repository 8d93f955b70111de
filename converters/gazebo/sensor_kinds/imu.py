"""`<sensor type="imu">`: SDF `imu.sdf`, with per-axis noise (1.6+) or SDF 1.5's shared noise."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from typing import Any

from converters.description.sensors import NO_NOISE3, ImuSpec, Noise
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind


@sensor_kind("imu", "imu")
def read_imu(reader: SensorReader, common: dict[str, Any], placement: Placement) -> ImuSpec:
    """Noise of angular velocity [rad/s] and linear acceleration [m/s²]; `enable_orientation`."""
    imu = reader.el.find("imu")
    angular, linear = NO_NOISE3, NO_NOISE3
    orientation = True
    if imu is not None:
        angular = _axes_noise(reader, imu, "angular_velocity", "rate")
        linear = _axes_noise(reader, imu, "linear_acceleration", "accel")
        orientation = reader.flag("imu/enable_orientation", True)
    return ImuSpec(
        **common,
        angular_velocity_noise=angular,
        linear_acceleration_noise=linear,
        enable_orientation=orientation,
    )


def _axes_noise(
    reader: SensorReader, imu: ET.Element, group: str, legacy: str
) -> tuple[Noise, Noise, Noise]:
    """Per-axis noise (1.6+: `<group><x><noise>`), else SDF 1.5's `<noise><legacy>` for all."""
    old = imu.find(f"noise/{legacy}")
    if old is not None:
        kind = reader.text("noise/type", "gaussian", imu).lower()
        shared = dataclasses.replace(reader.noise(old), type=kind)
        return (shared, shared, shared)
    return reader.vector_noise(imu, group)
