"""Sensor checks: an IMU at rest reads gravity, a lidar sees a wall at its known distance, a
contact sensor fires exactly while its link touches the ground.

Each check reads the robot's Gazebo sensors (the converter's records) in the scenario's world,
noise-free (the noise is Gazebo's draw, not physics), against an oracle computed here: the
specific force Rᵀ·(−g) of a still sensor, the slab intersection of each ray with the scenario's
box, and MuJoCo's geom-to-plane distance (`mj_geomDistance`) for touching. A robot without
sensors of the kind is skipped with the reason, never failed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from twin_cli.validate.checks.base import RobotUnderTest, Series, Status, bars, judged, result
from twin_cli.validate.checks.sim import PLANE, ScenarioRun
from twin_cli.validate.scenario import Scenario

TOUCH_BAND_M = 1e-9  # [m] |geom-to-ground distance| this small is not judged (grazing)


def _of_type(robot: RobotUnderTest, kind: str) -> list[Any]:
    from converters.description import sensors as specs

    wanted = {"imu": specs.ImuSpec, "ray": specs.RaySpec, "contact": specs.ContactSpec}[kind]
    return [s for s in robot.sensors if isinstance(s, wanted)]


def _skip(check: str, kind: str) -> Any:
    return result(
        check, "physics", Status.SKIP, "no sensor", "n/a",
        details=[f"the robot declares no <sensor type='{kind}'> (URDF <gazebo> or SDF link)"],
    )  # fmt: skip


def _bound(run: ScenarioRun, spec: Any) -> Any:
    from twin_cli.sensors.noise import sensor_rng
    from twin_cli.sensors.suite import SENSOR_TYPES

    sensor = SENSOR_TYPES[type(spec)](spec, run.entity, sensor_rng(0, spec.name))
    sensor.bind(run.world.model)
    return sensor


def _evaluated(run: ScenarioRun) -> Any:
    """The live data with forward dynamics and body accelerations of the current state."""
    import mujoco

    model, data = run.world.model, run.world.data
    mujoco.mj_forward(model, data)
    mujoco.mj_rnePostConstraint(model, data)
    return data


def check_sensor_imu(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """IMU at rest: mean specific force Rᵀ·(a − g) within `tol_m_s2`, angular velocity within
    `max_rate_rad_s`, over the settled second half (sampled every step).

    A robot "at rest" on chattering contacts still drifts a little; its mean acceleration over
    the window, a = Δv/T of the sensor's site, is taken into the oracle, so the check judges
    the sensor (frame, pose, gravity included), not how still the robot stands.
    """
    imus = _of_type(robot, "imu")
    if not imus:
        return _skip("sensor_imu", "imu")
    run = ScenarioRun(robot, scenario)
    sensors = [_bound(run, s) for s in imus]
    samples: dict[str, list[np.ndarray]] = {s.spec.name: [] for s in sensors}
    gravity = np.array(run.world.model.opt.gravity)

    def sample(r: ScenarioRun) -> None:
        if r.time < scenario.duration / 2:
            return
        with r.world.lock:
            data = _evaluated(r)
            for sensor in sensors:
                samples[sensor.spec.name].append(_imu_sample(r, sensor, data, gravity))

    run.run(scenario.duration, sample, every=1)
    dt = float(run.world.model.opt.timestep)
    hints, worst, biases = [], 0.0, {}
    for name, rows in samples.items():
        table = np.array(rows)  # per step: f − Rᵀ(−g) (3), gyro (3), R (9), site velocity (3)
        mean_a = (table[-1, 15:18] - table[0, 15:18]) / (dt * (len(table) - 1))
        R = table[:-1, 6:15].mean(axis=0).reshape(3, 3)
        bias = float(np.linalg.norm(table[:-1, 0:3].mean(axis=0) - R.T @ mean_a))
        spin = float(np.linalg.norm(table[:, 3:6].mean(axis=0)))
        worst = max(worst, bias)
        biases[name] = bias
        if bias > th["tol_m_s2"] or spin > th["max_rate_rad_s"]:
            hints.append(
                f"IMU '{name}' at rest reads {bias:.3g} m/s² off Rᵀ·(a − g) and "
                f"{spin:.3g} rad/s: check its <pose> and that its link is the one it moves with"
            )
    plot = bars("specific force off Rᵀ·(a − g)", "m/s²", biases, th["tol_m_s2"], x_label="IMU")
    return judged(
        "sensor_imu", "physics", f"{worst:.3g} m/s² off gravity",
        f"≤ {th['tol_m_s2']:g} m/s²", hints, series=[plot],
    )  # fmt: skip


def _imu_sample(run: ScenarioRun, sensor: Any, data: Any, gravity: np.ndarray) -> np.ndarray:
    import mujoco

    values = sensor.compute(run.world.model, data)
    R = data.site_xmat[sensor.site].reshape(3, 3)
    velocity = np.zeros(6)
    site = mujoco.mjtObj.mjOBJ_SITE
    mujoco.mj_objectVelocity(run.world.model, data, site, sensor.site, velocity, 0)
    return np.concatenate([values[7:10] - R.T @ (-gravity), values[4:7], R.ravel(), velocity[3:]])


def ray_box_distance(origin: np.ndarray, dirs: np.ndarray, centre, half, R) -> np.ndarray:
    """Distance [m] along each unit ray to a box (centre, half sizes, rotation), +inf if missed
    (the slab method, in the box frame)."""
    o = R.T @ (origin - centre)
    d = dirs @ R
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (-half - o) / d, (half - o) / d
    near = np.nanmax(np.minimum(t1, t2), axis=1)
    far = np.nanmin(np.maximum(t1, t2), axis=1)
    return np.where((near <= far) & (near > 0), near, np.inf)


def check_sensor_lidar(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Lidar and wall: rays that reach the scenario's box read its distance within `tol_m`."""
    lidars = _of_type(robot, "ray")
    if not lidars or not scenario.obstacles:
        return _skip("sensor_lidar", "ray")
    run = ScenarioRun(robot, scenario)
    run.run(scenario.duration)
    box = run.world.model.body("obstacle0/box").id
    worst, seen, hints, plots = 0.0, 0, [], []
    with run.world.lock:
        data = _evaluated(run)
        centre, R = data.xpos[box].copy(), data.xmat[box].reshape(3, 3).copy()
        for spec in lidars:
            sensor = _bound(run, spec)
            measured = sensor.ranges(run.world.model, data)
            origin = data.site_xpos[sensor.site]
            dirs = sensor.local_dirs @ data.site_xmat[sensor.site].reshape(3, 3).T
            half = np.array(scenario.obstacles[0].size) / 2.0
            expected = ray_box_distance(origin, dirs, centre, half, R)
            ground = np.where(dirs[:, 2] < 0, -origin[2] / np.minimum(dirs[:, 2], -1e-12), np.inf)
            judged_rays = (expected >= spec.range_min) & (expected <= spec.range_max)
            judged_rays &= expected < ground
            seen += int(judged_rays.sum())
            error = np.abs(measured[judged_rays] - expected[judged_rays])
            off = float(np.max(np.where(np.isfinite(error), error, 1e9), initial=0.0))
            worst = max(worst, off)
            plots.append(_ray_errors(spec.name, np.flatnonzero(judged_rays), error, th["tol_m"]))
            if off > th["tol_m"]:
                hints.append(
                    f"lidar '{spec.name}': a ray reads {off:.3g} m off the box's distance: "
                    "check its <pose>, <min_angle>/<max_angle> and <range>"
                )
    if not seen:
        return _no_ray_reaches(scenario)
    return judged(
        "sensor_lidar", "physics", f"{worst:.3g} m over {seen} rays", f"≤ {th['tol_m']:g} m", hints,
        series=[p for p in plots if p.t],
    )  # fmt: skip


def _ray_errors(name: str, rays: np.ndarray, error: np.ndarray, tol: float) -> Series:
    """|measured − slab distance| [m] of each ray that reaches the box, by ray index."""
    shown = np.where(np.isfinite(error), error, np.nan)  # a missed ray leaves a gap
    return Series(
        f"lidar {name} range error",
        "m",
        tuple(float(i) for i in rays),
        {"|measured − oracle|": tuple(float(e) for e in shown)},
        threshold=tol,
        x_label="ray index",
    )


def _no_ray_reaches(scenario: Scenario) -> Any:
    return result(
        "sensor_lidar", "physics", Status.SKIP, "no ray reaches the box", "n/a",
        details=[f"no lidar ray meets the scenario's box within its range ({scenario.name})"],
    )  # fmt: skip


def check_sensor_contact(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Contact sensors on the ground: each fires exactly at the samples its collision geoms
    touch the ground (`mj_geomDistance` ≤ 0), and is silent while they are apart."""
    contacts = _of_type(robot, "contact")
    if not contacts:
        return _skip("sensor_contact", "contact")
    run = ScenarioRun(robot, scenario)
    sensors = [_bound(run, s) for s in contacts]
    ground = [g for g in range(run.world.model.ngeom) if run.world.model.geom_type[g] == PLANE]
    wrong: dict[str, int] = {s.spec.name: 0 for s in sensors}
    touched: dict[str, int] = {s.spec.name: 0 for s in sensors}

    def sample(r: ScenarioRun) -> None:
        with r.world.lock:
            data = _evaluated(r)
            for sensor in sensors:
                gap = _ground_gap(r.world.model, data, sensor.geoms, ground)
                if abs(gap) <= TOUCH_BAND_M:
                    continue
                fired = sensor.read(r.world.model, data, r.time).in_contact
                touched[sensor.spec.name] += gap < 0
                wrong[sensor.spec.name] += fired != (gap < 0)

    run.run(scenario.duration, sample, every=10)
    hints = [
        f"contact sensor '{n}' disagreed with its link's touching the ground at {k} samples: "
        "check its <contact><collision> names the link's collision"
        for n, k in wrong.items()
        if k > th["max_wrong_samples"]
    ]
    summary = ", ".join(f"{n}: touching {touched[n]}" for n in wrong)
    plot = bars(
        "samples disagreeing with the touch oracle", "samples", wrong, th["max_wrong_samples"],
        x_label="contact sensor",
    )  # fmt: skip
    return judged(
        "sensor_contact", "physics", f"{sum(wrong.values())} wrong samples ({summary})",
        f"≤ {th['max_wrong_samples']:g}", hints, series=[plot],
    )  # fmt: skip


def _ground_gap(model: Any, data: Any, geoms: frozenset[int], ground: list[int]) -> float:
    """The smallest signed distance [m] between the geoms and the ground planes."""
    import mujoco

    gaps = [
        mujoco.mj_geomDistance(model, data, g, plane, 0.05, None) for g in geoms for plane in ground
    ]
    return float(min(gaps, default=np.inf))
