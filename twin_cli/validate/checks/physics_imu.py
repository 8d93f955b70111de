"""IMU check: at rest each IMU reads the specific force of its site, and spreads no more than
its declared noise allows.

Mean (noise-free readings, every step of the settled second half): the specific force of a
still sensor is Rᵀ·(a − g); a robot "at rest" on chattering contacts still drifts a little, so
its mean acceleration over the window, a = Δv/T of the sensor's site, is taken into the oracle
and the check judges the sensor (frame, pose, gravity included), not how still the robot stands.

Spread: a real IMU at rest reads its datasheet noise; the simulated one reads the physics'
jitter at rest (contacts chattering, a held posture ringing) plus the noise its `<noise>`
declares, independent, so their variances add: σ_reading² = σ_jitter² + σ_declared². Gazebo's
noise is white, drawn per reading, so σ_jitter is the white part of the noise-free readings
taken at the sensor's own update period: std(x[k+1] − x[k])/√2 (the Allan deviation at one
period), which motion slower than the readings (a settle, a slow rock) hardly reaches. An axis
whose σ_reading exceeds `max_noise_factor` × σ_declared fails: a filter tuned on the declared
noise would be fed a much noisier sensor than the robot's description says. Axes without
declared noise are not judged (there is nothing to compare with).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from twin_cli.validate.checks.base import CheckResult, RobotUnderTest, Series, bars, judged
from twin_cli.validate.checks.sensor_access import bound, evaluated, no_sensor, sensors_of_type
from twin_cli.validate.checks.sim import ScenarioRun
from twin_cli.validate.scenario import Scenario

if TYPE_CHECKING:
    import mujoco

    from twin_cli.sensors.kinds.imu import ImuSensor

QUANTITIES = (("specific force", "m/s²", slice(0, 3)), ("angular velocity", "rad/s", slice(3, 6)))


@dataclass(frozen=True)
class ImuFigures:
    """What one IMU read at rest: mean error [m/s²], mean turn rate [rad/s], and per axis (xyz
    specific force, then xyz angular velocity) the jitter and the declared noise σ."""

    name: str
    link: str
    bias: float
    spin: float
    jitter: np.ndarray  # (6,)
    declared: np.ndarray  # (6,), 0 where no noise is declared

    def noise_ratios(self) -> np.ndarray:
        """σ_reading / σ_declared per axis with declared noise (NaN elsewhere)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            total = np.sqrt(self.jitter**2 + self.declared**2)
            return np.where(self.declared > 0, total / self.declared, np.nan)


def _imu_sample(
    run: ScenarioRun, sensor: ImuSensor, data: mujoco.MjData, gravity: np.ndarray
) -> np.ndarray:
    """f − Rᵀ(−g) (3), gyro (3), R (9), site velocity (3): one noise-free sample."""
    import mujoco

    values = sensor.compute(run.world.model, data)
    R = data.site_xmat[sensor.site].reshape(3, 3)
    velocity = np.zeros(6)
    site = mujoco.mjtObj.mjOBJ_SITE
    mujoco.mj_objectVelocity(run.world.model, data, site, sensor.site, velocity, 0)
    return np.concatenate([values[7:10] - R.T @ (-gravity), values[4:7], R.ravel(), velocity[3:]])


def _rest_tables(run: ScenarioRun, sensors: list, duration: float) -> dict[str, np.ndarray]:
    """Per IMU, one `_imu_sample` row per step over the second half of `duration` [s]."""
    rows: dict[str, list[np.ndarray]] = {s.spec.name: [] for s in sensors}
    gravity = np.array(run.world.model.opt.gravity)

    def sample(r: ScenarioRun) -> None:
        if r.time < duration / 2:
            return
        with r.world.lock:
            data = evaluated(r)
            for sensor in sensors:
                rows[sensor.spec.name].append(_imu_sample(r, sensor, data, gravity))

    run.run(duration, sample, every=1)
    return {name: np.array(table) for name, table in rows.items()}


def _figures(sensor: ImuSensor, table: np.ndarray, dt: float) -> ImuFigures:
    mean_a = (table[-1, 15:18] - table[0, 15:18]) / (dt * (len(table) - 1))
    R = table[:-1, 6:15].mean(axis=0).reshape(3, 3)
    bias = float(np.linalg.norm(table[:-1, 0:3].mean(axis=0) - R.T @ mean_a))
    spin = float(np.linalg.norm(table[:, 3:6].mean(axis=0)))
    rate = float(sensor.spec.update_rate)
    every = max(1, round(1.0 / (rate * dt))) if rate > 0 else 1  # steps between readings
    readings = table[::every, 0:6]
    jitter = np.std(np.diff(readings, axis=0), axis=0) / np.sqrt(2.0)
    declared = np.concatenate([sensor.accel_noise.stddev, sensor.gyro_noise.stddev])
    return ImuFigures(sensor.spec.name, sensor.spec.link, bias, spin, jitter, declared)


def _mean_hints(f: ImuFigures, th: dict[str, float]) -> list[str]:
    """Why the mean reading is off: a robot that is not at rest, or a reading that disagrees
    with the physics of a still site (a twin bug)."""
    if f.spin > th["max_rate_rad_s"]:
        return [
            f"IMU '{f.name}': the robot is not at rest (the IMU turns at {f.spin:.3g} rad/s on "
            f"average, > {th['max_rate_rad_s']:g}, and reads {f.bias:.3g} m/s² off Rᵀ·(a − g)): "
            "start it in a posture it holds still (-J NAME=POS or [robot] joints; "
            "friction_standing and ground_contact show how it moves)"
        ]
    if f.bias > th["tol_m_s2"]:
        return [
            f"IMU '{f.name}': still, it reads {f.bias:.3g} m/s² off the specific force of its "
            "site Rᵀ·(a − g): the simulated reading disagrees with the physics; a twin bug, "
            "report it with this robot"
        ]
    return []


def _noise_hints(f: ImuFigures, factor: float) -> list[str]:
    """The quantities whose spread at rest exceeds `factor` × the declared noise."""
    hints, ratios = [], f.noise_ratios()
    for quantity, unit, axes in QUANTITIES:
        worst = np.nanargmax(np.nan_to_num(ratios[axes], nan=-1.0)) + axes.start
        if not ratios[worst] > factor:
            continue
        axis = "xyz"[worst - axes.start]
        total = float(np.hypot(f.jitter[worst], f.declared[worst]))
        hints.append(
            f"IMU '{f.name}' on link '{f.link}': at rest its {quantity} ({axis}) spreads "
            f"{total:.3g} {unit}, {ratios[worst]:.3g}× its declared noise "
            f"{f.declared[worst]:.3g} {unit} (> {factor:g}×): the robot itself shakes it by "
            f"{f.jitter[worst]:.3g} {unit}; damp what shakes (the <kd> of the links that "
            "touch, or the hold's gains), or declare the noise the sensor really has "
            "(<noise><stddev>)"
        )
    return hints


def check_sensor_imu(
    robot: RobotUnderTest, scenario: Scenario, th: dict[str, float]
) -> CheckResult:
    """IMU at rest: mean specific force Rᵀ·(a − g) within `tol_m_s2`, mean angular velocity
    within `max_rate_rad_s`, spread ≤ `max_noise_factor` × the declared noise."""
    imus = sensors_of_type(robot, "imu")
    if not imus:
        return no_sensor("sensor_imu", "imu", robot)
    run = ScenarioRun(robot, scenario)
    sensors = [bound(run, s) for s in imus]
    tables = _rest_tables(run, sensors, scenario.duration)
    dt = float(run.world.model.opt.timestep)
    figures = [_figures(s, tables[s.spec.name], dt) for s in sensors]
    factor = th["max_noise_factor"]
    hints = [h for f in figures for h in _mean_hints(f, th) + _noise_hints(f, factor)]
    worst = max(f.bias for f in figures)
    ratios = {f.name: float(np.nanmax(f.noise_ratios(), initial=0.0)) for f in figures}
    noise = f"noise {max(ratios.values()):.3g}× declared" if any(ratios.values()) else "no noise"
    return judged(
        "sensor_imu", "physics", f"{worst:.3g} m/s² off gravity, {noise}",
        f"≤ {th['tol_m_s2']:g} m/s², ≤ {factor:g}× declared noise", hints, value=worst,
        details=[_describe(f) for f in figures], series=_plots(figures, ratios, th),
    )  # fmt: skip


def _describe(f: ImuFigures) -> str:
    spread = ", ".join(f"{v:.3g}" for v in f.jitter)
    return (
        f"IMU '{f.name}': {f.bias:.3g} m/s² off, turning {f.spin:.3g} rad/s; white spread of "
        f"its noise-free readings at rest (ax ay az [m/s²] gx gy gz [rad/s]) {spread}"
    )


def _plots(figures: list[ImuFigures], ratios: dict[str, float], th: dict) -> list[Series]:
    biases = {f.name: f.bias for f in figures}
    plots = [bars("specific force off Rᵀ·(a − g)", "m/s²", biases, th["tol_m_s2"], x_label="IMU")]
    declared = {n: r for n, r in ratios.items() if r > 0}
    if declared:
        label = "IMU (reading spread at rest over declared noise, worst axis)"
        plots.append(bars("spread over declared noise", "1", declared, th["max_noise_factor"],
                          x_label=label))  # fmt: skip
    return plots
