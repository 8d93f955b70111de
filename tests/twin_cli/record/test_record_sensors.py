"""Sensor topics in a recording, read back with rosbags' AnyReader against the world's readings.

Two identical worlds step the same deterministic trajectory: one is recorded, the other is read
through `SensorSuite` at every sensor period; the bag must carry exactly those readings.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from models import write_urdf
from record_helpers import read_bag, seconds
from sensor_models import bumper_ball, imu_box, lidar_post

from twin_cli.record import BagRecording
from twin_cli.sensors import SensorSuite
from twin_cli.world import Pose, World

IMU_RATE, SCAN_RATE = 200.0, 10.0  # [Hz]
DURATION_STEPS = 300  # 0.3 s of 1 ms steps


def _world(tmp_path: Path) -> World:
    world = World()
    world.spawn(
        write_urdf(tmp_path, imu_box(rate=IMU_RATE), "imu.urdf"), name="imu", pose=Pose(z=0.3)
    )
    world.spawn(
        write_urdf(tmp_path, bumper_ball(), "ball.urdf"), name="ball", pose=Pose(x=1, z=0.2)
    )
    lidar = lidar_post(rate=SCAN_RATE, samples=31)
    world.spawn(write_urdf(tmp_path, lidar, "lidar.urdf"), name="lidar", pose=Pose(x=-1))
    return world


def test_sensor_topics_carry_the_worlds_readings_at_their_rates(tmp_path):
    recorded, reference = _world(tmp_path), _world(tmp_path)
    path = tmp_path / "sensors.mcap"
    recording = BagRecording(recorded, path).start()
    for _ in range(DURATION_STEPS // 5):
        recorded.step(5)
    assert recording.stop().error is None
    suites = {n: SensorSuite(reference, n) for n in ("imu", "ball", "lidar")}
    expected: dict[str, dict[float, object]] = {}
    for _ in range(DURATION_STEPS + 1):  # every step: the bumper updates at each
        for entity, suite in suites.items():
            for name, reading in suite.read().items():
                expected.setdefault(f"{entity}/{name}", {})[round(reading.time, 9)] = reading
        reference.step(1)
    bag = read_bag(path)
    topics = {  # gazebo_ros naming under the entity's namespace: <topic>, else the sensor name
        f"{entity}/{name}": f"/{entity}/{(spec.topic or name).strip('/')}"
        for entity, suite in suites.items()
        for name, spec in suite.specs.items()
    }
    assert "/imu/imu" in bag, sorted(bag)
    imu = bag["/imu/imu"]
    stamps = np.array([seconds(m.header.stamp) for _, m in imu])
    assert np.allclose(np.diff(stamps), 1 / IMU_RATE, atol=1e-9), "IMU at its update rate"
    for _, m in imu:
        want = expected["imu/imu"][round(seconds(m.header.stamp), 9)]
        got = m.linear_acceleration
        assert (got.x, got.y, got.z) == tuple(want.linear_acceleration)
        q = m.orientation
        assert (q.x, q.y, q.z, q.w) == tuple(want.orientation)
        assert m.header.frame_id == f"imu/{want.frame_id}", "the link's tf frame"
    ((scan, scan_topic),) = [(k, t) for k, t in topics.items() if k.startswith("lidar/")]
    scans = bag[scan_topic]
    assert len(scans) == 4, "10 Hz over 0.3 s: t = 0, 0.1, 0.2, 0.3"
    for _, m in scans:
        want = expected[scan][round(seconds(m.header.stamp), 9)]
        np.testing.assert_array_equal(m.ranges, np.float32(want.ranges))  # LaserScan is float32
    ((contact, contact_topic),) = [(k, t) for k, t in topics.items() if k.startswith("ball/")]
    touching = [m for _, m in bag[contact_topic] if m.states]
    assert touching, "the ball lands within 0.3 s"
    for m in touching:
        want = expected[contact][round(seconds(m.header.stamp), 9)]
        assert [s.collision2_name for s in m.states] == [c.collision2 for c in want.states]
        f = m.states[0].total_wrench.force
        assert (f.x, f.y, f.z) == tuple(want.states[0].force)


def test_the_live_streams_worker_publishes_sensor_topics_too(tmp_path):
    """`Recording` (the worker thread behind the Foxglove stream) with a bag sink: the same
    sensor topics, announced with the others, at the sensor's rate."""
    from twin_cli.record import BagSink, Recording

    world = World()
    world.spawn(write_urdf(tmp_path, imu_box(rate=IMU_RATE), "imu.urdf"), name="imu")
    path = tmp_path / "live.mcap"
    recording = Recording(world, [BagSink(path)], rate=30.0).start()
    world.step(100)
    assert recording.stop().error is None
    last = SensorSuite(world, "imu").read()["imu"]  # the newest sample MuJoCo kept
    bag = read_bag(path)
    stamps = [seconds(m.header.stamp) for _, m in bag["/imu/imu"]]
    # Every 200 Hz sample MuJoCo kept, at its own sim time: t = 0 ... 0.095 s (the sample of
    # t = 0.1 s is computed at the start of the step after the last one).
    assert np.allclose(stamps, [k / IMU_RATE for k in range(20)], atol=1e-9), stamps
    assert last.time == pytest.approx(stamps[-1], abs=1e-12)
    a = bag["/imu/imu"][-1][1].linear_acceleration
    assert (a.x, a.y, a.z) == tuple(last.linear_acceleration)
    assert "/imu/joint_states" in bag, "the world's topics stay announced"


@pytest.mark.parametrize("spawned_at", [37, 137, 251])
def test_a_spawn_mid_recording_keeps_every_sensor_on_its_rate_grid(tmp_path, spawned_at):
    """A spawn changes the model, and the recording reads every sensor once after it (a sensor
    spawned into a paused world has a reading at once) and registers its sensor observers
    again; apart from that reading the lidar's scans stay at k/rate of sim time, before and
    after (as a Gazebo sensor keeps its update grid), and the spawned lidar's join that grid."""
    world = _world(tmp_path)
    path = tmp_path / "spawn.mcap"
    recording = BagRecording(world, path).start()
    world.step(spawned_at)
    lidar = write_urdf(tmp_path, lidar_post(rate=SCAN_RATE, samples=31), "second.urdf")
    world.spawn(lidar, name="second", pose=Pose(x=-2))
    world.step(600 - spawned_at)
    assert recording.stop().error is None
    bag = read_bag(path)
    for topic in ("/lidar/scan", "/second/scan"):
        stamps = np.array([seconds(m.header.stamp) for _, m in bag[topic]])
        # The reading the model change brings: the first at or after the spawn, taken at the
        # recording's next state sample, which notices the new model (measured 3-9 ms after
        # the spawn), off the grid.
        first = np.flatnonzero(stamps >= spawned_at * 1e-3 - 1e-9)[0]
        off = stamps[first] * SCAN_RATE
        assert stamps[first] - spawned_at * 1e-3 <= 0.01 and abs(off - round(off)) > 1e-6, (
            f"{topic}: no reading at the model change: {stamps}"
        )
        stamps = np.delete(stamps, first)
        assert len(stamps) >= 3, f"{topic}: {len(stamps)} scans"
        grid = stamps * SCAN_RATE
        assert np.allclose(grid, np.round(grid), atol=1e-6), f"{topic} off its grid: {stamps}"
        assert len(set(np.round(grid))) == len(grid), f"{topic} scanned twice: {stamps}"
