"""A live recording with `max_wall_rate` (the ROS 2 bridge's) thins a world that runs faster than
real time to that many samples per wall second, and sends every sample of a slower one."""

from __future__ import annotations

import time
from pathlib import Path

import scenarios
from twin_cli.record import Recording
from twin_cli.world import Pose, World

HUMANOID = Path(scenarios.HUMANOID)
WALL_RATE = 50.0  # [Hz] of wall time allowed
SLACK = 1.5  # a burst of one period at the start, and a busy machine's late wake-ups


class _Count:
    def __init__(self) -> None:
        self.clocks: list[float] = []

    def set_topics(self, topics: list) -> None:
        """Unused: only /clock is counted."""

    def write(self, message) -> None:
        if message.topic == "/clock":
            self.clocks.append(message.time)

    def close(self) -> None:
        """Nothing to close."""


def test_a_paced_live_recording_takes_at_most_its_wall_rate_of_a_fast_world() -> None:
    world = World()
    world.spawn(HUMANOID, name="h", pose=Pose(z=1.0))
    sink = _Count()
    recording = Recording(world, [sink], rate=100.0, latest_only=True, max_wall_rate=WALL_RATE)
    recording.start()
    start = time.monotonic()
    while time.monotonic() - start < 1.0:
        world.step(100)  # unthrottled: several times real time
    wall = time.monotonic() - start
    sim = float(world.data.time)
    recording.stop()
    assert sim > 2.0 * wall, f"the world ran only {sim / wall:.1f}x real time: no test"
    assert len(sink.clocks) <= SLACK * WALL_RATE * wall + 2, f"{len(sink.clocks)} in {wall} s"
    assert len(sink.clocks) >= 0.5 * WALL_RATE * wall, "the paced recording starved"
    assert sink.clocks == sorted(sink.clocks) and sink.clocks[-1] >= sim - 0.5, "not the newest"
