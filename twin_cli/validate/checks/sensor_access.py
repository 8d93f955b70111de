"""What the sensor checks share: the robot's sensors of a kind, bound to a scenario's world.

Sensors are read noise-free where a check compares them with physics (the noise is Gazebo's
draw, not physics); a robot without a sensor of the kind gets a not-applicable verdict naming
why, including a sensor of the kind that sits on a link the robot does not have.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, not_applicable
from twin_cli.validate.checks.sim import ScenarioRun

if TYPE_CHECKING:
    import mujoco

    from converters.description.sensors import SensorSpec

# Gazebo `<sensor type>` values of each kind a check reads.
TYPES = {"imu": ("imu",), "ray": ("ray", "gpu_ray", "lidar", "gpu_lidar"), "contact": ("contact",)}


def sensors_of_type(robot: RobotUnderTest, kind: str) -> list[Any]:
    """The robot's converted sensors of `kind` ("imu", "ray" or "contact")."""
    from converters.description import sensors as specs

    wanted = {"imu": specs.ImuSpec, "ray": specs.RaySpec, "contact": specs.ContactSpec}[kind]
    return [s for s in robot.sensors if isinstance(s, wanted)]


def no_sensor(check: str, kind: str, robot: RobotUnderTest) -> CheckResult:
    """Not applicable: the robot has no sensor of `kind` on any of its links."""
    lost = [s for s in robot.unplaced_sensors if s.kind in TYPES[kind]]
    if lost:
        where = ", ".join(f"'{s.name}' on missing link '{s.link}'" for s in lost)
        reason = f"its <sensor type='{kind}'> is not on the robot ({where}; see sensor_links)"
    else:
        reason = f"the robot declares no <sensor type='{kind}'> (URDF <gazebo> or SDF link)"
    return not_applicable(check, "physics", "no sensor", reason)


def bound(run: ScenarioRun, spec: SensorSpec) -> Any:
    """The twin sensor simulating `spec` on the run's robot, bound to its world's model."""
    from twin_cli.sensors.noise import sensor_rng
    from twin_cli.sensors.registry import sensor_class

    sensor = sensor_class(type(spec))(spec, run.entity, sensor_rng(0, spec.name))
    sensor.bind(run.world.model)
    return sensor


def evaluated(run: ScenarioRun) -> mujoco.MjData:
    """The live data with forward dynamics and body accelerations of the current state."""
    import mujoco

    model, data = run.world.model, run.world.data
    mujoco.mj_forward(model, data)
    mujoco.mj_rnePostConstraint(model, data)
    return data
