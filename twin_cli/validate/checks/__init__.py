"""The validation checks, one function each, registered by name with their default thresholds.

Model checks read the converted robot only; physics checks step it in the world a scenario
describes. A scenario's `[thresholds]` override the defaults listed here (same keys, SI units).
Importing this package imports no mujoco: check functions import it when they run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from twin_cli.validate.checks import (
    model_collision,
    model_effort,
    model_ignored,
    model_inertia,
    model_joints,
    model_sensors,
    physics_contact,
    physics_dynamics,
    physics_friction,
    physics_gravity,
    physics_imu,
    physics_realtime,
    physics_sensors,
    physics_tracking,
)
from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, Series, Status


@dataclass(frozen=True)
class Check:
    """A registered check: `kind` is "model" or "physics"; `defaults` are its thresholds."""

    name: str
    kind: str
    run: Callable[..., CheckResult]
    defaults: dict[str, float]
    summary: str


def _check(name: str, kind: str, run: Callable[..., CheckResult], **defaults: float) -> Check:
    return Check(name, kind, run, defaults, (run.__doc__ or "").strip().splitlines()[0])


CHECKS: dict[str, Check] = {
    c.name: c
    for c in (
        _check("inertial", "model", model_inertia.check_inertial, min_mass=1e-6),
        _check("inertia_tensor", "model", model_inertia.check_inertia_tensor, triangle_tol=1e-6),
        _check("inertia_plausible", "model", model_inertia.check_inertia_plausible, min_ratio=0.01),
        _check(
            "mesh_complexity",
            "model",
            model_collision.check_mesh_complexity,
            warn_triangles=1000,
            max_triangles=10000,
        ),
        _check(
            "initial_overlap", "model", model_collision.check_initial_overlap, tolerance_m=0.001
        ),
        _check("joint_definitions", "model", model_joints.check_joint_definitions),
        _check("gravity_hold", "model", model_effort.check_gravity_hold, min_effort_ratio=1.0),
        _check("sensor_links", "model", model_sensors.check_sensor_links),
        _check("ignored_parts", "model", model_ignored.check_ignored_parts),
        _check("gravity", "physics", physics_gravity.check_gravity, rel_tol=0.01),
        _check(
            "zero_gravity",
            "physics",
            physics_gravity.check_zero_gravity,
            max_com_drift_m=0.001,
            max_link_motion_m=0.01,
        ),
        _check(
            "moon_gravity",
            "physics",
            physics_gravity.check_moon_gravity,
            rel_tol=0.01,
            expected_ratio=1.62 / 9.81,
        ),
        _check(
            "ground_contact",
            "physics",
            physics_contact.check_ground_contact,
            max_penetration_m=0.005,
            rest_speed_m_s=0.05,
        ),
        _check(
            "friction_standing",
            "physics",
            physics_friction.check_friction_standing,
            max_slip_m=0.005,
            settle_s=0.5,
        ),
        _check(
            "friction_incline",
            "physics",
            physics_friction.check_friction_incline,
            stick_factor=0.8,
            slide_factor=1.25,
            max_stick_slip_m=0.01,
            min_slide_ratio=0.5,
            max_probes=2,
        ),
        _check("collision", "physics", physics_contact.check_collision, max_intrusion_m=0.05),
        _check(
            "joint_limits",
            "physics",
            physics_dynamics.check_joint_limits,
            max_violation_rad=0.05,
            max_violation_m=0.01,
            settle_fraction=0.7,
        ),
        _check("inertia", "physics", physics_dynamics.check_inertia, rel_tol=0.01, torque_n_m=1.0),
        _check(
            "stability",
            "physics",
            physics_dynamics.check_stability,
            max_energy_gain=0.05,
            max_spin_rad_s=100.0,
        ),
        _check(
            "realtime",
            "physics",
            physics_realtime.check_realtime,
            min_factor=0.8,
            min_cpu_share=0.5,
            max_cpu_spread=1.5,
        ),
        _check(
            "sensor_imu",
            "physics",
            physics_imu.check_sensor_imu,
            tol_m_s2=0.05,
            max_rate_rad_s=0.01,
            max_noise_factor=3.0,
        ),
        _check("sensor_lidar", "physics", physics_sensors.check_sensor_lidar, tol_m=0.001),
        _check(
            "sensor_contact", "physics", physics_sensors.check_sensor_contact, max_wrong_samples=0
        ),
        _check(
            "tracking",
            "physics",
            physics_tracking.check_tracking,
            max_settle_s=1.0,
            max_sine_error_fraction=0.2,
            max_speed_ratio=1.05,
            max_runaway_ratio=4.0,
        ),
    )
}

MODEL_CHECKS = [c.name for c in CHECKS.values() if c.kind == "model"]
PHYSICS_CHECKS = [c.name for c in CHECKS.values() if c.kind == "physics"]

__all__ = [
    "CHECKS",
    "MODEL_CHECKS",
    "PHYSICS_CHECKS",
    "Check",
    "CheckResult",
    "RobotUnderTest",
    "Series",
    "Status",
]
