"""The stepping thread stays responsive at absurdly low update rates (found by the API fuzz)."""

from __future__ import annotations

import time

import pytest

from twin_cli.world import World, WorldSettings


def test_a_rate_change_and_stop_are_seen_while_the_next_step_is_hours_away() -> None:
    world = World(WorldSettings(rate=1000.0))
    world.start()
    try:
        time.sleep(0.1)
        world.set_physics(rate=1e-4)  # [Hz]: the next step is due in 10,000 s
        time.sleep(0.3)
        world.set_physics(rate=1000.0)
        before = world.stats().sim_time
        time.sleep(0.5)
        advanced = world.stats().sim_time - before
        assert advanced == pytest.approx(0.5, abs=0.15), "back at real time within 0.05 s [s]"
    finally:
        start = time.perf_counter()
        world.stop()
        assert time.perf_counter() - start < 1.0, "stop waited for a step hours away"
