"""The live bridge's thinning of an IMU's kept samples: a world far faster than real time gets
at most `wall_share` × rate of them a wall second (the newest), a bag every one."""

from __future__ import annotations

import time

import pytest
from models import write_urdf
from sensor_models import imu_box

from twin_cli.record.sensor_feed import KEPT, SensorFeed
from twin_cli.world import Pose, World

IMU_RATE = 100.0  # [Hz] of sim time
SIM_S = 0.5  # [s] stepped between two looks, unthrottled; within the IMU's kept history


@pytest.mark.parametrize("wall_share", [None, 2.0])
def test_an_imus_kept_samples_are_thinned_to_the_wall_share(tmp_path, wall_share) -> None:
    world = World()
    world.spawn(write_urdf(tmp_path, imu_box(rate=IMU_RATE), "imu.urdf"), name="imu", pose=Pose())
    feed = SensorFeed(world)
    feed.wall_share = wall_share
    assert feed.rates(), "the IMU has no observer rate"
    with world.lock:
        feed.capture(KEPT)  # the first look: samples from here on are new
    start = time.monotonic()
    world.step(round(SIM_S / world.model.opt.timestep))
    with world.lock:
        readings = feed.build(feed.capture(KEPT))
    wall = time.monotonic() - start
    if wall_share is None:
        assert len(readings) == pytest.approx(SIM_S * IMU_RATE, abs=1), "a bag keeps every one"
        return
    allowed = wall * wall_share * IMU_RATE
    assert wall < SIM_S / 4, f"the world stepped at {SIM_S / wall:.1f}x real time: too slow here"
    count = len(readings)
    assert 1 <= count <= max(1.0, allowed) + 1, f"{count} readings in {wall:.4f} s wall"
    times = [r.time for _, r in readings]
    assert times[-1] == pytest.approx(float(world.data.time), abs=1.5 / IMU_RATE), "not the newest"
