"""An echo on a world stepped by hand: every message at the topic's sim-time rate while it runs,
none after `stop`, whose thread removes its observers."""

from __future__ import annotations

import time

import pytest
from models import block
from sensor_models import imu_box

from twin_cli.live import Echo, find_topic
from twin_cli.live.catalogue import live_topics
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World


def _wait(predicate, timeout: float = 10.0) -> None:  # noqa: ANN001
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    assert predicate(), "timed out"


@pytest.fixture
def world() -> World:
    world = World()
    world.spawn(SpawnRequest(xml=block(size=0.2, name="box")), name="box", pose=Pose(z=1.0))
    world.spawn(SpawnRequest(xml=imu_box()), name="imu", pose=Pose(x=1.0, z=0.5))
    return world


def test_echo_sends_each_sample_at_the_topics_rate_and_nothing_after_stop(world):
    got: list[dict] = []
    echo = Echo(world, find_topic(world, "box/joint_states"), got.append).start()
    world.step(100)  # 0.1 s at 1 ms: samples at 0, 0.01, ..., 0.1
    _wait(lambda: len(got) == 11)
    assert [round(m["time"], 9) for m in got] == [round(0.01 * k, 9) for k in range(11)]
    assert {m["topic"] for m in got} == {"/box/joint_states"}
    echo.stop()
    _wait(lambda: echo.stopped)
    world.step(100)
    time.sleep(0.05)
    assert len(got) == 11, "no message after stop: the observer is gone"


def test_a_sensor_echo_sends_every_reading_of_that_sensor(world):
    got: list[dict] = []
    echo = Echo(world, find_topic(world, "/imu/imu"), got.append).start()
    world.step(500)  # 0.5 s of a 200 Hz IMU, read from MuJoCo's kept samples
    _wait(lambda: len(got) >= 50)
    echo.stop()
    times = [m["time"] for m in got]
    assert all(abs(b - a - 0.005) < 1e-9 for a, b in zip(times, times[1:], strict=False)), times
    assert got[0]["type"] == "sensor_msgs/msg/Imu"
    assert got[0]["message"]["header"]["frame_id"] == "imu/imu_link"


ROS_NAME = r"^(/[A-Za-z_][A-Za-z0-9_]*)+$"  # a ROS 2 topic name: segments of [A-Za-z0-9_]


@pytest.mark.parametrize(
    ("name", "segment"),
    [("imu box", "imu_box"), ("Ünïcödé körper", "Unicode_korper"), ("2nd imu", "_2nd_imu")],
)
def test_an_entity_named_with_spaces_or_accents_publishes_valid_ros_topics(name, segment):
    """The entity keeps its name; its topics live under one valid ROS segment of it."""
    import re

    world = World()
    world.spawn(SpawnRequest(xml=imu_box()), name=name, pose=Pose(z=0.5))
    assert world.entity_names() == [name]
    topics = [t.name for t in live_topics(world) if t.entity == name]
    assert f"/{segment}/joint_states" in topics, topics
    assert all(re.match(ROS_NAME, t) for t in topics), topics
    assert any(t.startswith(f"/{segment}/") and t != f"/{segment}/joint_states" for t in topics)
    assert find_topic(world, f"{segment}/joint_states").entity == name
