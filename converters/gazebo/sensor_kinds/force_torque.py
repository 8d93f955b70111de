"""`<sensor type="force_torque">` on a joint: SDF `force_torque.sdf`, and the gazebo_ros F/T
plugin's noise."""

from __future__ import annotations

from typing import Any

from converters.description.sensors import NO_NOISE3, ForceTorqueSpec, Noise
from converters.gazebo.sensors import Placement, SensorReader, sensor_kind

PLUGIN_NOISE_TAGS = ("gaussianNoise", "gaussian_noise")  # gazebo_ros F/T plugins, [N] and [N m]
FRAMES = ("child", "parent", "sensor")  # SDF `<force_torque><frame>`
DIRECTIONS = ("child_to_parent", "parent_to_child")  # SDF `<measure_direction>`


@sensor_kind("force_torque", "force_torque")
def read_force_torque(
    reader: SensorReader, common: dict[str, Any], placement: Placement
) -> ForceTorqueSpec:
    """Frame, measure direction, the joint's bodies and the noise of force [N], torque [N m].

    Raises:
        GazeboTagError: a frame or measure direction SDF does not define.
    """
    frame = reader.text("force_torque/frame", "child").lower()
    direction = reader.text("force_torque/measure_direction", "child_to_parent").lower()
    for tag, value, allowed in (
        ("frame", frame, FRAMES),
        ("measure_direction", direction, DIRECTIONS),
    ):
        if value not in allowed:
            raise reader.ctx.fail(
                f"{reader.prefix} force_torque/{tag}", value, " or ".join(allowed)
            )
    ft = reader.el.find("force_torque")
    force, torque = NO_NOISE3, NO_NOISE3
    if ft is not None:
        force = reader.vector_noise(ft, "force")
        torque = reader.vector_noise(ft, "torque")
    if not any(n.active for n in force + torque):
        force = torque = _plugin_noise(reader)
    return ForceTorqueSpec(
        **common,
        joint=placement.joint,
        frame=frame,
        measure_direction=direction,
        child_body=placement.body,
        parent_body=placement.parent_body,
        force_noise=force,
        torque_noise=torque,
    )


def _plugin_noise(reader: SensorReader) -> tuple[Noise, Noise, Noise]:
    """The gazebo_ros F/T plugin's `<gaussianNoise>` (ROS 1) or `<gaussian_noise>` (ROS 2):
    a zero-mean Gaussian of that standard deviation on every axis, as the plugin adds it."""
    for plugin in reader.el.findall("plugin"):
        for tag in PLUGIN_NOISE_TAGS:
            stddev = reader.number(tag, 0.0, plugin)
            if stddev > 0.0:
                noise = Noise("gaussian", stddev=stddev)
                return (noise, noise, noise)
    return NO_NOISE3
