"""The bridge observes a world faster than its publisher's wall rate at a whole fraction of the
state rate (`live_recording.stride`), and a real-time world at the full rate.

The live tests run a real publisher process with a Cyclone DDS participant in a loopback domain
of this module's own, so nothing leaves the machine.
"""

from __future__ import annotations

import math
import os
import time

import pytest
from models import write_urdf
from sensor_models import imu_box

from twin_cli.ros.live_recording import SPEED_CHECK_S, RosRecording, stride
from twin_cli.ros.scope import scope_from
from twin_cli.world import Pose, World, WorldSettings

RATE = 100.0  # [Hz] of sim time
WALL_RATE = 200.0  # [1/s] the publisher's most samples a wall second (WALL_SPEEDUP × RATE)
# Apart from test_ros_live's 30-69, and below the ephemeral ports as those are.
DOMAIN_ID = str(70 + os.getpid() % 20)
RUN_S = 3.0  # [s] wall: several speed checks


@pytest.mark.parametrize(
    ("speed", "expected"),
    [
        (0.0, 1),  # paused
        (-3.0, 1),  # the clock went back (reset, load)
        (math.nan, 1),
        (1.0, 1),  # real time: every sample
        (2.0, 1),  # twice real time: 200 a wall second, the publisher's most
        (3.9, 1),  # 390 a wall second: the publisher takes the newest 200
        (4.0, 2),  # every second sample: 200 a wall second
        (15.0, 7),  # an unthrottled humanoid: 214 a wall second
        (1000.0, 500),
    ],
)
def test_stride_is_the_most_that_leaves_the_wall_rate(speed, expected) -> None:
    assert stride(speed, RATE, WALL_RATE) == expected, f"stride at {speed}x real time"


def _recording(world: World) -> RosRecording:
    scope = scope_from({"ROS_DOMAIN_ID": DOMAIN_ID})
    return RosRecording(world, scope, rate=RATE, max_wall_rate=WALL_RATE)


def test_an_unthrottled_world_is_sampled_at_about_the_publishers_wall_rate(tmp_path) -> None:
    """A small world runs hundreds of times real time: the bridge takes every k-th sample of
    its 100 Hz grid, so the loop makes about WALL_RATE observer calls a wall second, not
    RATE × speed."""
    world = World(WorldSettings(rate=0.0))  # unthrottled
    world.spawn(write_urdf(tmp_path, imu_box(rate=RATE), "imu.urdf"), name="imu", pose=Pose())
    recording = _recording(world).start()
    try:
        assert recording.ready(), recording.status().error
        world.start()
        time.sleep(2 * SPEED_CHECK_S)  # the first checks made
        before, sim_before, start = (
            recording.status().samples,
            world.stats().sim_time,
            time.monotonic(),
        )
        time.sleep(RUN_S)
        samples, sim = recording.status().samples - before, world.stats().sim_time - sim_before
        wall = time.monotonic() - start
        world.stop()
    finally:
        recording.stop(patience=10.0)
    speed = sim / wall
    assert speed > 8, f"the world ran at {speed:.1f}x real time: too slow here to need a stride"
    assert recording.stride >= 2, f"stride {recording.stride} at {speed:.0f}x real time"
    on_grid = sim * RATE  # samples a full-rate observer would have taken
    assert samples < on_grid / 2, f"{samples} samples of {on_grid:.0f} grid points"
    assert WALL_RATE / 3 * wall < samples < 3 * WALL_RATE * wall, f"{samples} in {wall:.2f} s"


def test_a_real_time_world_is_observed_at_the_full_rate(tmp_path) -> None:
    """At real time the bridge's stride stays 1 at every speed check: every sample of the 100 Hz
    grid is taken (whether a starved publisher sends each is the token bucket's matter)."""
    world = World(WorldSettings(rate=1000.0))
    world.spawn(write_urdf(tmp_path, imu_box(rate=RATE), "imu.urdf"), name="imu", pose=Pose())
    recording = _recording(world).start()
    strides = []
    try:
        assert recording.ready(), recording.status().error
        world.start()
        for _ in range(round(RUN_S / (SPEED_CHECK_S / 2))):
            time.sleep(SPEED_CHECK_S / 2)
            strides.append(recording.stride)
        world.stop()
    finally:
        recording.stop(patience=10.0)
    assert set(strides) == {1}, f"strides {strides} in real time"
