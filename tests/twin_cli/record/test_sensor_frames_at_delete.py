"""A sensor reading keeps the frame its entity's tf tree named when it was captured, even when
the entity is deleted before the reading is built (the recorder builds readings in a thread of
its own, a backlog of up to a quarter second behind the stepping): a deleted robot's last scans
and IMU samples name frames that its last `/tf_static` published, prefixed with its name."""

from __future__ import annotations

import pytest
from models import write_urdf
from sensor_models import imu_box, lidar_post

from twin_cli.record.sensor_feed import SensorFeed
from twin_cli.world import Pose, World

STEPS = 100  # 0.2 s at MuJoCo's 2 ms step: the IMU keeps samples, the lidar is due


@pytest.mark.parametrize("deleted", ["post", "imu"])
def test_readings_captured_before_a_delete_keep_the_prefixed_frames(tmp_path, deleted) -> None:
    world = World()
    world.spawn(write_urdf(tmp_path, lidar_post(rate=10.0, samples=31), "l.urdf"), name="post")
    imu = write_urdf(tmp_path, imu_box(rate=100.0), "imu.urdf")
    world.spawn(imu, name="imu", pose=Pose(y=2, z=0.3))
    feed = SensorFeed(world)
    feed.rates()
    with world.lock:
        feed.capture()  # the IMU's kept samples count from this first look on
    world.step(STEPS)
    with world.lock:
        captured = feed.capture()  # every sensor, before the delete
    world.delete(deleted)
    world.step(STEPS)
    with world.lock:
        feed.capture()  # the stepping thread's next look follows the delete
    frames = {topic.name: reading.frame_id for topic, reading in feed.build(captured)}
    assert frames.get("/post/scan") == "post/scan", frames
    imu_frames = {frames[name] for name in frames if name.startswith("/imu/")}
    assert imu_frames and all(f.startswith("imu/") for f in imu_frames), frames
