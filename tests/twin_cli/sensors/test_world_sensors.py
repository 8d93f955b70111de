"""Sensors read from real worlds, against physics oracles (gravity, geometry, statics, contact)."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from corpus_registry import CORPUS, PACKAGES_ROOT, needs_corpus, package_paths
from models import write_urdf
from sensor_models import bumper_ball, hanging_load, imu_box, lidar_post

from twin_cli.errors import PartNotFoundError
from twin_cli.sensors import Reading, SensorSuite
from twin_cli.sensors.history import SensorHistory
from twin_cli.sensors.suite import period_slot
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

STATIC = "<gazebo><static>true</static></gazebo>\n</robot>"
N_DRAWS = 10_000


def _world_with(tmp_path: Path, text: str, name: str, pose: Pose = Pose()) -> World:
    world = World()
    world.spawn(write_urdf(tmp_path, text, f"{name}.urdf"), name=name, pose=pose)
    return world


def _gravity(world: World) -> float:
    return float(np.linalg.norm(world.model.opt.gravity))


def _site_rotation(world: World, site: str) -> np.ndarray:
    mujoco.mj_forward(world.model, world.data)
    return world.data.site(site).xmat.reshape(3, 3).copy()


def _wall(x: float, name: str = "wall") -> mujoco.MjSpec:
    """A static 0.1 m thick, 4 m wide, 2 m high box whose near face is the plane x = `x`."""
    spec = mujoco.MjSpec()
    spec.modelname = name
    spec.worldbody.add_geom(
        type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 2.0, 1.0], pos=[x + 0.05, 0.0, 1.0]
    )
    return spec


# ----------------------------------------------------------------------------------------- IMU
def test_imu_lying_still_reads_gravity_up_and_zero_rate_in_its_own_frame(tmp_path: Path) -> None:
    text = (
        imu_box(yaw=0.5).replace('rpy="0 0 0.5"', 'rpy="0.3 -0.2 0.5"').replace("</robot>", STATIC)
    )
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    world.step(20)
    reading = SensorSuite(world, "imu").read()["imu"]
    R = _site_rotation(world, "imu/sensor:imu")
    expected = R.T @ np.array([0.0, 0.0, _gravity(world)])  # f = a − g with a = 0
    np.testing.assert_allclose(reading.linear_acceleration, expected, atol=1e-9)
    np.testing.assert_allclose(reading.angular_velocity, 0.0, atol=1e-12)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, R.reshape(-1))
    x, y, z, w = reading.orientation
    assert abs(float(np.dot(quat, [w, x, y, z]))) == pytest.approx(1.0, abs=1e-12), "orientation"


def test_imu_on_a_flat_resting_box_reads_plus_g_on_z(tmp_path: Path) -> None:
    text = imu_box().replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    world.step(5)
    reading = SensorSuite(world, "imu").read()["imu"]
    np.testing.assert_allclose(reading.linear_acceleration, [0, 0, _gravity(world)], atol=1e-9)


def test_imu_in_free_fall_reads_zero_specific_force(tmp_path: Path) -> None:
    world = _world_with(tmp_path, imu_box(), "imu", Pose(z=5.0))
    world.step(100)  # 0.1 s: falling 5 cm, far from the ground
    reading = SensorSuite(world, "imu").read()["imu"]
    np.testing.assert_allclose(reading.linear_acceleration, 0.0, atol=1e-9)


def test_noisy_imu_samples_have_the_tags_mean_and_stddev(tmp_path: Path) -> None:
    mean, stddev = 0.05, 0.02
    text = imu_box(stddev=stddev, mean=mean).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    sensor = SensorSuite(world, "imu")._sensors["imu"]
    clean = np.zeros((N_DRAWS, 3))
    draws = sensor.accel_noise.apply(clean)
    se_mean = stddev / math.sqrt(N_DRAWS)
    se_std = stddev / math.sqrt(2 * (N_DRAWS - 1))
    for axis in range(3):
        got_mean, got_std = draws[:, axis].mean(), draws[:, axis].std(ddof=1)
        assert abs(got_mean - mean) < 3 * se_mean, f"axis {axis} mean {got_mean}"
        assert abs(got_std - stddev) < 3 * se_std, f"axis {axis} stddev {got_std}"


def test_noise_bias_is_drawn_once_with_a_random_sign_and_runs_are_reproducible(
    tmp_path: Path,
) -> None:
    text = imu_box(stddev=1e-6, bias_mean=0.3).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    signs = [
        np.sign(SensorSuite(world, "imu", seed=seed)._sensors["imu"].gyro_noise.bias[0])
        for seed in range(400)
    ]
    positive = signs.count(1.0)
    assert abs(positive - 200) < 3 * 10, f"{positive} of 400 biases positive (binomial ½)"
    first = SensorSuite(world, "imu", seed=7).read()["imu"]
    again = SensorSuite(world, "imu", seed=7).read()["imu"]
    assert first == again, "same seed, same state: same reading"
    assert abs(abs(first.angular_velocity[0]) - 0.3) < 1e-4, "gyro x reads ± the bias at rest"


# --------------------------------------------------------------------------------------- lidar
def test_lidar_two_metres_from_a_wall_reads_the_walls_geometry(tmp_path: Path) -> None:
    world = _world_with(tmp_path, lidar_post(), "post")
    world.spawn(_wall(2.0), name="wall")
    scan = SensorSuite(world, "post").read()["lidar"]
    angles = scan.angle_min + scan.angle_increment * np.arange(len(scan.ranges))
    ranges = np.array(scan.ranges)
    centre = len(ranges) // 2
    assert ranges[centre] == pytest.approx(2.0, abs=1e-9), "central ray"
    # The wall is 4 m wide: rays at |θ| < atan(2/2) hit the plane x = 2 at 2/cos θ.
    on_wall = np.abs(np.tan(angles)) * 2.0 < 2.0 - 1e-6
    np.testing.assert_allclose(ranges[on_wall], 2.0 / np.cos(angles[on_wall]), atol=1e-9)
    beyond = np.abs(angles) > math.atan2(2.0, 2.0) + 0.05  # past the wall's edge: nothing
    assert np.isinf(ranges[beyond]).all(), "rays past the wall read +inf"
    assert scan.range_min == 0.12 and scan.range_max == 3.5


def test_lidar_reads_inf_beyond_max_range_and_noise_within_range(tmp_path: Path) -> None:
    world = _world_with(tmp_path, lidar_post(range_max=1.5, stddev=0.01), "post")
    world.spawn(_wall(2.0), name="wall")
    scan = SensorSuite(world, "post").read()["lidar"]
    assert np.isinf(scan.ranges).all(), "a wall at 2 m is beyond a 1.5 m lidar"
    near = _world_with(tmp_path, lidar_post(stddev=0.01, samples=1, min_angle=0, max_angle=0), "p")
    near.spawn(_wall(1.0), name="wall")
    suite = SensorSuite(near, "p")
    draws = []
    for _ in range(200):
        near.step(100)  # 10 Hz: one fresh scan per 0.1 s
        draws.append(suite.read()["lidar"].ranges[0])
    assert abs(np.mean(draws) - 1.0) < 3 * 0.01 / math.sqrt(200), "noisy ranges centre on 1 m"


def test_lidar_does_not_see_its_own_robot(tmp_path: Path) -> None:
    world = _world_with(tmp_path, lidar_post(samples=8, min_angle=-3.1, max_angle=3.1), "post")
    scan = SensorSuite(world, "post").read()["lidar"]
    assert np.isinf(scan.ranges).all(), f"own post and scanner housing hidden: {scan.ranges}"


# ------------------------------------------------------------------------------ force / torque
@pytest.mark.parametrize("mass", [0.5, 3.0])
def test_force_torque_under_a_static_load_reads_m_g(tmp_path: Path, mass: float) -> None:
    world = _world_with(tmp_path, hanging_load(mass), "hang")
    world.step(200)
    wrench = SensorSuite(world, "hang").read()["ft"]
    np.testing.assert_allclose(wrench.force, [0, 0, mass * _gravity(world)], rtol=1e-6, atol=1e-6)
    # The load's centre of mass is 0.1 m below the joint, straight down: no moment about it.
    np.testing.assert_allclose(wrench.torque, 0.0, atol=1e-6)


def test_force_torque_child_to_parent_is_the_reaction(tmp_path: Path) -> None:
    world = _world_with(tmp_path, hanging_load(2.0, direction="child_to_parent"), "hang")
    world.step(50)
    wrench = SensorSuite(world, "hang").read()["ft"]
    assert wrench.force[2] == pytest.approx(-2.0 * _gravity(world), rel=1e-6)


F_STD, T_STD = 0.5, 0.05  # [N], [N m] per axis
FT_DRAWS = 2_000


def _assert_noise_law(values: np.ndarray, expected: np.ndarray, stddev: float) -> None:
    """Each column's mean is `expected` within 3 standard errors and its sample std is
    `stddev` within 3 standard errors of a std estimate (σ/√(2(n−1)), Gaussian)."""
    n = len(values)
    se_mean, se_std = stddev / math.sqrt(n), stddev / math.sqrt(2 * (n - 1))
    for axis in range(values.shape[1]):
        got_mean, got_std = values[:, axis].mean(), values[:, axis].std(ddof=1)
        assert abs(got_mean - expected[axis]) < 3 * se_mean, f"axis {axis} mean {got_mean}"
        assert abs(got_std - stddev) < 3 * se_std, f"axis {axis} stddev {got_std}"


def test_noisy_force_torque_readings_scatter_around_m_g_with_the_tags_stddev(
    tmp_path: Path,
) -> None:
    mass = 2.0
    world = _world_with(tmp_path, hanging_load(mass, rate=1000.0, noise=(F_STD, T_STD)), "hang")
    world.step(100)
    g = _gravity(world)
    suite = SensorSuite(world, "hang")
    polled = []
    for _ in range(FT_DRAWS):  # one reading per 1 ms period: a fresh draw each time
        world.step(1)
        polled.append(suite.read()["ft"])
    fed = _fed(world, ["hang"], FT_DRAWS)  # one call: noise drawn for each batch at once
    assert len(fed) == FT_DRAWS + 1, "one per period, and the one at the start"
    for readings in (polled, fed):
        force = np.array([r.force for r in readings])
        torque = np.array([r.torque for r in readings])
        _assert_noise_law(force, np.array([0.0, 0.0, mass * g]), F_STD)
        _assert_noise_law(torque, np.zeros(3), T_STD)


def _fed(world: World, entities: list[str], steps: int) -> list[Reading]:
    """Every reading a recording takes (`twin_cli.record.sensor_feed`, the recorders' sensor
    path) over one `world.step(steps)` call: a capture at the start, one world observer per
    rate the feed asks for, a last look at the samples MuJoCo kept; built afterwards."""
    from twin_cli.record.sensor_feed import KEPT, SensorFeed

    feed = SensorFeed(world, entities)
    rates = feed.rates()
    with world.lock:
        captured = feed.capture()
    handles = [world.add_observer(lambda r=r: captured.extend(feed.capture(r)), r) for r in rates]
    world.step(steps)
    with world.lock:
        captured.extend(feed.capture(KEPT))
    for handle in handles:
        world.remove_observer(handle)
    return [reading for _, reading in feed.build(captured)]


# ------------------------------------------------------------------------------------- contact
def test_bumper_reports_contact_exactly_while_the_ball_touches(tmp_path: Path) -> None:
    radius = 0.05
    world = _world_with(tmp_path, bumper_ball(radius), "ball", Pose(z=0.2))
    suite = SensorSuite(world, "ball")
    body = world.model.body("ball/ball").id
    touching, reported = [], []
    for _ in range(600):
        world.step(1)
        with world.lock:
            mujoco.mj_kinematics(world.model, world.data)
            gap = float(world.data.xpos[body][2]) - radius  # height of the ball's lowest point
        reading = suite.read()["bumper"]
        touching.append(gap <= 0.0)
        reported.append(reading.in_contact)
    assert any(touching), "the ball reached the ground"
    assert reported == touching, "contact reported exactly at the steps the ball touches"
    resting = suite.read()["bumper"]
    mass = 0.5
    assert resting.total_force[2] == pytest.approx(mass * _gravity(world), rel=0.05)
    assert resting.states[0].collision2 == "ground"


# -------------------------------------------------------------------------------- update rates
def test_a_reading_is_refreshed_only_once_per_period_of_sim_time(tmp_path: Path) -> None:
    text = imu_box(rate=50.0).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    suite = SensorSuite(world, "imu")
    stamps = set()
    for _ in range(100):
        world.step(1)
        stamps.add(suite.read()["imu"].time)
    # MuJoCo computes the IMU at the start of each 20 ms period and keeps the samples with their
    # times; a request reads the newest: t = 0 ... 0.08 s (that of 0.1 s comes with step 101).
    expected = [0.0, 0.02, 0.04, 0.06, 0.08]
    np.testing.assert_allclose(sorted(stamps), expected, atol=1e-9, err_msg="50 Hz stamps")
    assert period_slot(0.2, 5.0, 0.001) == 1 and period_slot(0.1999, 5.0, 0.001) == 0


def test_a_bad_sensor_name_lists_the_entitys_sensors(tmp_path: Path) -> None:
    world = _world_with(tmp_path, lidar_post(), "post")
    with pytest.raises(PartNotFoundError, match=r"no sensor \[nope\].*lidar"):
        SensorSuite(world, "post").read(["nope"])


# ---------------------------------------------------------------------------------- turtlebot3
@needs_corpus
def test_turtlebot3_lidar_sees_a_box_one_metre_ahead() -> None:
    robot = CORPUS["turtlebot3_burger"]
    world = World()
    world.spawn(
        SpawnRequest(PACKAGES_ROOT / robot["entry"], package_paths=package_paths(robot)), name="tb3"
    )
    world.step(10)
    scan_origin = world.data.site("tb3/sensor:lds_lfcd_sensor").xpos.copy()
    world.spawn(_wall(float(scan_origin[0]) + 1.0, "box"), name="box")
    suite = SensorSuite(world, "tb3")
    assert set(suite.names) == {"imu", "lds_lfcd_sensor"}
    scan = suite.read()["lds_lfcd_sensor"]
    assert len(scan.ranges) == 360 and scan.range_max == 3.5 and scan.range_min == 0.12
    ahead = scan.ranges[0]  # angle 0: the robot's +x
    assert ahead == pytest.approx(1.0, abs=5 * 0.01), f"range ahead {ahead} (noise stddev 0.01)"
    behind = scan.ranges[180]
    assert math.isinf(behind), "nothing behind within 3.5 m"
    # The IMU updates every step (no <update_rate>). A robot that stays where it is has zero
    # mean acceleration, so its specific force averages to +g even while its contacts chatter.
    vertical = []
    for _ in range(1000):
        world.step(1)
        vertical.append(suite.read(["imu"])["imu"].linear_acceleration[2])
    assert np.mean(vertical) == pytest.approx(_gravity(world), abs=0.02), "mean IMU z over 1 s"


# ------------------------------------------------------------------------------------- stream
def test_a_recordings_feed_takes_every_reading_at_the_sensors_rates(tmp_path: Path) -> None:
    world = _world_with(tmp_path, lidar_post(samples=31), "post")
    world.spawn(_wall(2.0), name="wall")
    box = imu_box(rate=200.0, stddev=0.02).replace("</robot>", STATIC)
    world.spawn(write_urdf(tmp_path, box, "imu.urdf"), name="imu", pose=Pose(x=-3.0, z=0.1))
    world.step(10)  # the box settles on its contacts' first steps
    start = world.data.time
    readings = _fed(world, ["imu", "post"], 1000)  # one call: 1 s of sim time
    imus = [r for r in readings if r.sensor == "imu"]
    scans = [r for r in readings if r.sensor != "imu"]
    # 200 Hz: the samples MuJoCo kept, each at the start of its 5 ms period (that of t = 1 s is
    # computed with the next step); 10 Hz: the scan at the start and one per 0.1 s period.
    np.testing.assert_allclose([r.time for r in imus], start + 0.005 * np.arange(200), atol=1e-9)
    np.testing.assert_allclose([r.time for r in scans], start + 0.1 * np.arange(11), atol=1e-9)
    for scan in scans:
        assert scan.ranges[len(scan.ranges) // 2] == pytest.approx(2.0, abs=1e-9)
    # The static box: specific force +g on z, noise 0.02 m/s² per axis over 200 draws.
    z = np.array([r.linear_acceleration[2] for r in imus])
    assert abs(z.mean() - _gravity(world)) < 3 * 0.02 / math.sqrt(len(z)) + 1e-9
    assert abs(z.std(ddof=1) - 0.02) < 3 * 0.02 / math.sqrt(2 * (len(z) - 1))


# ------------------------------------------------------------------------- SDF joint sensors
HANGING_SDF = """<sdf version="1.7"><model name="hanging">
  <link name="support"><pose>0 0 1 0 0 0</pose><inertial><mass>1</mass><inertia><ixx>0.01</ixx>
    <iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>
  <joint name="mount" type="fixed"><parent>world</parent><child>support</child></joint>
  <link name="load"><pose>0 0 0.7 0 0 0</pose><inertial><pose>0 0 -0.1 0 0 0</pose>
    <mass>{mass}</mass><inertia><ixx>0.01</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial>
  </link>
  <joint name="hook" type="prismatic"><parent>support</parent><child>load</child>
    <axis><xyz>1 0 0</xyz><limit><lower>0</lower><upper>0</upper></limit></axis>
    <sensor name="ft" type="force_torque"><update_rate>100</update_rate>
      <force_torque><frame>child</frame><measure_direction>parent_to_child</measure_direction>
      </force_torque></sensor></joint>
</model></sdf>"""


@pytest.mark.parametrize("mass", [0.5, 3.0])
def test_sdf_joint_force_torque_sensor_reads_m_g(tmp_path: Path, mass: float) -> None:
    path = tmp_path / "hanging.sdf"
    path.write_text(HANGING_SDF.format(mass=mass))
    world = World()
    world.spawn(path, name="hang")
    world.step(200)
    suite = SensorSuite(world, "hang")
    assert suite.names == ["ft"] and suite.specs["ft"].joint == "hook"
    wrench = suite.read()["ft"]
    np.testing.assert_allclose(wrench.force, [0, 0, mass * _gravity(world)], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(wrench.torque, 0.0, atol=1e-6)  # COM straight below the joint


def test_an_imu_keeps_reading_after_a_time_only_reset(tmp_path: Path) -> None:
    """MuJoCo computes an IMU at its period from its last update time, kept in the sensor
    history; a time-only reset moves that history with the clock, so fresh samples follow."""
    text = imu_box(rate=200.0).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    world.step(300)
    world.reset(time_only=True)
    world.step(21)
    reading = SensorSuite(world, "imu").read()["imu"]
    assert reading.time == pytest.approx(0.020, abs=1e-9), (
        "the sample of t = 20 ms, not a stale one"
    )
    accel = np.array(reading.linear_acceleration)
    assert accel == pytest.approx([0.0, 0.0, 9.81], abs=0.05), "a static IMU reads +g"


def test_imu_samples_stay_on_the_period_grid_over_a_long_run(tmp_path: Path) -> None:
    """MuJoCo keeps each IMU sample with its time; over 20 s of 1 ms steps every one of the
    4,000 samples of a 200 Hz IMU sits on k · 5 ms (sums of 0.001 and of 0.005 drift apart by
    rounding, which put samples one step late: 2.001 s, 2.006 s, ...), also after a spawn
    (a new model) and a timestep change."""
    text = imu_box(rate=200.0).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    times: list[float] = []

    def collect(steps: int) -> None:
        model = world.model
        parts = [s for s in range(model.nsensor) if model.sensor_history[s][0] > 0]
        history = SensorHistory(model, parts)
        for _ in range(steps // 200):
            world.step(200)  # 40 samples, within the 100 the ring keeps
            new, _ = history.since(world.data, times[-1] if times else -0.001)
            times.extend(new)

    collect(10_000)
    world.spawn(_wall(5.0), name="wall")  # recompiled: the history moves to a new MjData
    collect(10_000)
    # A sample is computed at the start of its step: the one of t = 20 s comes with the next.
    assert len(times) == 4000 and times[0] == 0.0, "one sample per 5 ms, from t = 0"
    periods = np.asarray(times) / 0.005
    np.testing.assert_allclose(periods, np.round(periods), atol=1e-6, err_msg="on the grid")
    np.testing.assert_allclose(np.diff(times), 0.005, atol=1e-9)
    world.set_physics(timestep=0.0005)
    start = len(times)
    collect(2_000)  # 1 s more at the new step
    np.testing.assert_allclose(np.diff(times[start - 1 :]), 0.005, atol=1e-9)


def _imu_times(world: World, steps: int, after: float) -> list[float]:
    """Times of the IMU samples MuJoCo keeps over `steps` steps (looks every 20 steps)."""
    model = world.model
    parts = [s for s in range(model.nsensor) if model.sensor_history[s][0] > 0]
    history, times = SensorHistory(model, parts), [after]
    for _ in range(steps // 20):
        world.step(20)
        times.extend(history.since(world.data, times[-1])[0])
    return times[1:]


def test_an_imu_spawned_after_t0_samples_at_its_rate_from_its_spawn(tmp_path: Path) -> None:
    """MuJoCo starts a new sensor's tick at -period: spawned at t = 2 s it would be sampled at
    every step until the tick caught up (0.4 s of 1 ms samples). The world brings the tick to
    the clock, so the first sample is at the spawn and the next ones 5 ms apart."""
    world = World()
    world.step(2000)
    box = imu_box(rate=200.0).replace("</robot>", STATIC)
    world.spawn(write_urdf(tmp_path, box, "imu.urdf"), name="imu", pose=Pose(z=0.1))
    times = _imu_times(world, 200, after=1.999)
    np.testing.assert_allclose(times, 2.0 + 0.005 * np.arange(40), atol=1e-9)


def test_a_period_between_steps_samples_at_the_first_step_after_each_grid_point(
    tmp_path: Path,
) -> None:
    """400 Hz at 1 ms steps: grid points 2.5 ms apart fall on and between steps; each sample is
    at the first step at or after its grid point (as observers are), never before it."""
    text = imu_box(rate=400.0).replace("</robot>", STATIC)
    world = _world_with(tmp_path, text, "imu", Pose(z=0.1))
    times = np.asarray(_imu_times(world, 1000, after=-0.001))
    expected = np.ceil(np.round(0.0025 * np.arange(len(times)) / 0.001, 9)) * 0.001
    assert len(times) == 400
    np.testing.assert_allclose(times, expected, atol=1e-9)
