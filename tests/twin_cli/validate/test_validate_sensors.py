"""`twin validate`'s sensor checks on a robot that carries an IMU, a lidar and contact sensors.

The checks' oracles are computed in the checks (Rᵀ·(0, 0, g), ray-box slab distance,
mj_geomDistance to the ground); these tests run them through `validate` on real conversions and
assert the verdicts, the measured figures against the same physics, and the skips.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from models import write_urdf

import scenarios
from twin_cli.validate.checks.base import Status
from twin_cli.validate.checks.physics_sensors import ray_box_distance
from twin_cli.validate.runner import validate

SENSOR_CHECKS = ["sensor_imu", "sensor_lidar", "sensor_contact"]
INERTIA = 'ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"'
ROBOT = f"""<robot name="sensed">
  <link name="base"><inertial><mass value="2"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision></link>
  <joint name="foot_joint" type="fixed"><parent link="base"/><child link="foot"/>
    <origin xyz="0 0 -0.07"/></joint>
  <link name="foot"><inertial><mass value="0.2"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.3 0.2 0.04"/></geometry></collision></link>
  <joint name="bump_joint" type="fixed"><parent link="base"/><child link="bumper"/>
    <origin xyz="-0.22 0 0.02"/></joint>
  <link name="bumper"><inertial><mass value="0.1"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.04 0.3 0.05"/></geometry></collision></link>
  <joint name="imu_joint" type="fixed"><parent link="base"/><child link="imu_link"/>
    <origin xyz="0.1 0.05 0.0" rpy="0.4 -0.3 0.7"/></joint>
  <link name="imu_link"/>
  <joint name="mast_joint" type="fixed"><parent link="base"/><child link="mast"/>
    <origin xyz="0 0 0.2"/></joint>
  <link name="mast"><inertial><mass value="0.1"/><inertia {INERTIA}/></inertial>
    <collision><geometry><cylinder radius="0.03" length="0.05"/></geometry></collision></link>
  <gazebo reference="foot"><sensor type="contact" name="foot_contact"><update_rate>100</update_rate>
    <contact><collision>foot_collision</collision></contact></sensor></gazebo>
  <gazebo reference="bumper"><sensor type="contact" name="rear_bumper">
    <update_rate>100</update_rate><contact><collision>bumper_collision</collision></contact></sensor></gazebo>
  <gazebo reference="imu_link"><sensor type="imu" name="imu"><update_rate>200</update_rate>
    </sensor></gazebo>
  <gazebo reference="mast"><sensor type="ray" name="lidar"><update_rate>10</update_rate>
    <ray><scan><horizontal><samples>91</samples><min_angle>-0.7854</min_angle>
    <max_angle>0.7854</max_angle></horizontal></scan><range><min>0.1</min><max>5</max></range>
    </ray></sensor></gazebo>
</robot>"""


@pytest.fixture(scope="module")
def sensed(tmp_path_factory) -> dict:
    path = write_urdf(tmp_path_factory.mktemp("sensed"), ROBOT, "sensed.urdf")
    run = validate(path, scenarios=SENSOR_CHECKS, only=SENSOR_CHECKS)
    return {r.check: r for r in run.results}


def test_the_sensor_checks_pass_on_a_robot_that_carries_the_sensors(sensed) -> None:
    assert set(sensed) == set(SENSOR_CHECKS)
    for check, outcome in sensed.items():
        assert outcome.status is Status.PASS, (check, outcome.measured, outcome.hints)


def test_imu_check_measures_the_specific_force_of_rest(sensed) -> None:
    # Rᵀ·(0, 0, g) of a 0.4/−0.3/0.7 rad tilted IMU on a box at rest: within 0.05 m/s².
    measured = float(sensed["sensor_imu"].measured.split()[0])
    assert measured < 0.05, sensed["sensor_imu"].measured


def test_lidar_check_judges_the_rays_that_meet_the_wall(sensed) -> None:
    # 91 rays over ±45°; the 4 m wide wall 1 m ahead of the robot's front fills all of them.
    outcome = sensed["sensor_lidar"]
    worst, rays = outcome.measured.split()[0], int(outcome.measured.split()[3])
    assert rays == 91, outcome.measured
    assert float(worst) < 1e-6, "noise-free ranges equal the slab distances"


def test_contact_check_sees_the_foot_touch_and_the_bumper_stay_clear(sensed) -> None:
    measured = sensed["sensor_contact"].measured
    assert measured.startswith("0 wrong samples"), measured
    # 100 samples over 1 s: the resting foot touches at most of them (the rest are grazing,
    # |gap| ≤ 1e-9 m, or micro-separations where the sensor is rightly silent: 0 wrong).
    touching = int(measured.split("foot_contact: touching ")[1].split(",")[0])
    assert 50 <= touching <= 100, measured
    assert "rear_bumper: touching 0" in measured, "the bumper is 4 cm above the ground"


def test_robots_without_sensors_skip_the_sensor_checks_with_a_reason() -> None:
    run = validate(scenarios.HUMANOID, scenarios=SENSOR_CHECKS, only=SENSOR_CHECKS)
    for outcome in run.results:
        assert outcome.status is Status.NOT_APPLICABLE, (outcome.check, outcome.status)
        assert "declares no <sensor" in outcome.details[0]


def test_imu_check_fails_when_the_robot_is_not_at_rest(tmp_path: Path) -> None:
    # The same robot pushed with 200 N through the settled half slides (friction holds 24 N):
    # the IMU is not at rest, and the check fails saying so.
    # (at = 0.5505 s, mid-step: ScenarioRun.run misses an action at an exact multiple of the
    # step once sim time has accumulated rounding; a bug of sim.py reported to the lead.)
    path = write_urdf(tmp_path, ROBOT, "sensed.urdf")
    shaken = tmp_path / "shaken.toml"
    text = (Path(scenarios.__file__).parent / "sensor_imu.toml").read_text()
    shaken.write_text(
        text.replace('name = "sensor_imu"', 'name = "shaken"')
        + '\n[[actions]]\nkind = "push"\nat = 0.5505\nduration = 0.3\nforce = [200.0, 0.0, 0.0]\n'
    )
    run = validate(path, scenarios=[str(shaken)], only=["sensor_imu"])
    (outcome,) = run.results
    assert outcome.status is Status.FAIL, outcome.measured
    assert "IMU 'imu'" in outcome.hints[0]


def test_ray_box_oracle_is_d_over_cos_theta() -> None:
    # A ray at θ to the normal of a face 2 m away meets it at 2/cos θ; a ray away from it misses.
    angles = np.radians([0.0, 20.0, 40.0, 180.0])
    dirs = np.stack([np.cos(angles), np.sin(angles), np.zeros(4)], axis=1)
    got = ray_box_distance(
        np.zeros(3), dirs, np.array([2.5, 0, 0]), np.array([0.5, 5, 1]), np.eye(3)
    )
    np.testing.assert_allclose(got[:3], 2.0 / np.cos(angles[:3]), rtol=1e-12)
    assert np.isinf(got[3])


def test_each_sensor_check_plots_what_it_measured_with_its_threshold(sensed) -> None:
    from twin_cli.validate import report
    from twin_cli.validate.checks import CHECKS

    limits = {
        "sensor_imu": "tol_m_s2",
        "sensor_lidar": "tol_m",
        "sensor_contact": "max_wrong_samples",
    }
    for check, outcome in sensed.items():
        (series,) = outcome.series
        ax = report.figure("sensed", outcome, series).axes[0]
        red = [line for line in ax.get_lines() if line.get_color() == "red"]
        assert [float(line.get_ydata()[0]) for line in red] == [
            CHECKS[check].defaults[limits[check]]
        ]
    rays = sensed["sensor_lidar"].series[0]
    assert len(rays.t) == 91, "one error per ray that meets the wall"
    worst = float(np.nanmax(next(iter(rays.values.values()))))
    measured = float(sensed["sensor_lidar"].measured.split()[0])  # printed with 3 digits
    assert worst == pytest.approx(measured, rel=5e-3, abs=1e-12), "the plot's worst ray = verdict"
    assert sensed["sensor_contact"].series[0].categories == ("foot_contact", "rear_bumper")
