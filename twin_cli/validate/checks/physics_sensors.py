"""Sensor checks: a lidar sees a wall at its known distance, a contact sensor fires exactly
while its link touches the ground (the IMU's check is `physics_imu`).

Each check reads the robot's Gazebo sensors (the converter's records) in the scenario's world,
noise-free (the noise is Gazebo's draw, not physics), against an oracle computed here: the slab
intersection of each ray with the scenario's box, and MuJoCo's geom-to-plane distance
(`mj_geomDistance`) for touching. A robot without sensors of the kind is not applicable, with
the reason, never failed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from twin_cli.validate.checks.base import (
    CheckResult,
    RobotUnderTest,
    Series,
    bars,
    judged,
    not_applicable,
)
from twin_cli.validate.checks.sensor_access import bound, evaluated, no_sensor, sensors_of_type
from twin_cli.validate.checks.sim import PLANE, ScenarioRun
from twin_cli.validate.scenario import Scenario

if TYPE_CHECKING:
    import mujoco

TOUCH_BAND_M = 1e-9  # [m] |geom-to-ground distance| this small is not judged (grazing)


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
    lidars = sensors_of_type(robot, "ray")
    if not lidars:
        return no_sensor("sensor_lidar", "ray", robot)
    if not scenario.obstacles:
        reason = f"the scenario has no [[obstacles]] box for the lidar to see ({scenario.name})"
        return not_applicable("sensor_lidar", "physics", "no wall", reason)
    run = ScenarioRun(robot, scenario)
    run.run(scenario.duration)
    box = run.world.model.body("obstacle0/box").id
    worst, seen, hints, plots = 0.0, 0, [], []
    with run.world.lock:
        data = evaluated(run)
        centre, R = data.xpos[box].copy(), data.xmat[box].reshape(3, 3).copy()
        for spec in lidars:
            sensor = bound(run, spec)
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


def _no_ray_reaches(scenario: Scenario) -> CheckResult:
    reason = f"no lidar ray meets the scenario's box within its range ({scenario.name})"
    return not_applicable("sensor_lidar", "physics", "no ray reaches the box", reason)


def check_sensor_contact(robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]):
    """Contact sensors on the ground: each fires exactly at the samples its collision geoms
    touch the ground (`mj_geomDistance` ≤ 0), and is silent while they are apart."""
    contacts = sensors_of_type(robot, "contact")
    if not contacts:
        return no_sensor("sensor_contact", "contact", robot)
    run = ScenarioRun(robot, scenario)
    sensors = [bound(run, s) for s in contacts]
    ground = [g for g in range(run.world.model.ngeom) if run.world.model.geom_type[g] == PLANE]
    wrong: dict[str, int] = {s.spec.name: 0 for s in sensors}
    touched: dict[str, int] = {s.spec.name: 0 for s in sensors}

    def sample(r: ScenarioRun) -> None:
        with r.world.lock:
            data = evaluated(r)
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


def _ground_gap(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: frozenset[int], ground: list[int]
) -> float:
    """The smallest signed distance [m] between the geoms and the ground planes."""
    import mujoco

    gaps = [
        mujoco.mj_geomDistance(model, data, g, plane, 0.05, None) for g in geoms for plane in ground
    ]
    return float(min(gaps, default=np.inf))
