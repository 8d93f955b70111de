"""`<sensor type="ray">` and its other names (`gpu_ray`, `lidar`, `gpu_lidar`): SDF `ray.sdf`."""

from __future__ import annotations

from typing import Any

from converters.description.sensors import RaySpec
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind

# SDF's defaults of `<scan><horizontal|vertical><samples>` (ray.sdf).
SAMPLES = (("horizontal", 640), ("vertical", 1))


@sensor_kind("ray", "ray", "gpu_ray", "lidar", "gpu_lidar")
def read_ray(reader: SensorReader, common: dict[str, Any], placement: Placement) -> RaySpec:
    """The scan's samples, resolution and angles [rad] per direction, its range [m], its noise."""
    ray = reader.el.find("ray")
    ray = ray if ray is not None else reader.el.find("lidar")
    if ray is None:
        return RaySpec(**common)
    values: dict[str, Any] = {}
    for direction, samples in SAMPLES:
        path = f"scan/{direction}/"
        values[f"{direction}_samples"] = reader.integer(path + "samples", samples, ray)
        values[f"{direction}_resolution"] = reader.number(path + "resolution", 1.0, ray)
        values[f"{direction}_min_angle"] = reader.number(path + "min_angle", 0.0, ray)
        values[f"{direction}_max_angle"] = reader.number(path + "max_angle", 0.0, ray)
    return RaySpec(
        **common,
        **values,
        range_min=reader.number("range/min", 0.0, ray),
        range_max=reader.number("range/max", 0.0, ray),
        range_resolution=reader.number("range/resolution", 0.0, ray),
        noise=reader.noise(ray.find("noise")),
    )
