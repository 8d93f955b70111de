"""A recording's observers keep their k·period grid when the divergence watchdog replays a batch.

The watchdog restores the state of a batch's start and steps it again one step at a time; sim
time goes back within the batch, but that is no clock reset: a 10 Hz sensor observed from
t0 must still be called at t0 + k·0.1 s, once each, as Gazebo stamps a sensor on its own update
grid. The robot kicks itself past its velocity bound at every step (a 1 g link of 1e-4 kg m²
driven at 1000 N m: u·h/I = 1e4 rad/s against a bound of 100 × 1 rad/s), so every batch of
the run is replayed (batches under 100 steps: the link turns 10 rad a step and would reach its
±1000 rad stop, below the bound again when the batch ends).
"""

from __future__ import annotations

import numpy as np
import pytest
from models import write_urdf

from twin_cli.world import Pose, World

EFFORT = 1000.0  # [N m] the joint's effort limit, commanded in full
VELOCITY = 1.0  # [rad/s] its velocity limit: the watchdog's bound is 100 rad/s
BATCHES = 6  # of at most 90 steps: longer, the link reaches its stop and slows by the end
GRID_TOL = 1e-9  # [s] sim time against k·period: sums of 1 ms steps
KICKER = (
    '<robot name="kicker"><link name="base"><inertial><mass value="1"/><inertia ixx="0.01" '
    'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link><link name="arm">'
    '<inertial><mass value="0.001"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" '
    'ixz="0" iyz="0"/></inertial></link><joint name="kick" type="revolute"><parent '
    f'link="base"/><child link="arm"/><axis xyz="0 1 0"/><limit effort="{EFFORT}" '
    f'lower="-1000" upper="1000" velocity="{VELOCITY}"/></joint></robot>'
)


@pytest.mark.parametrize(
    ("origin_steps", "batch", "rate"), [(0, 50, 100.0), (37, 80, 10.0), (5, 60, 20.0)]
)
def test_observers_keep_their_grid_through_a_divergence_replay(
    tmp_path, origin_steps: int, batch: int, rate: float
) -> None:
    world = World()
    world.spawn(write_urdf(tmp_path, KICKER), name="kicker", pose=Pose(z=1.0))
    if origin_steps:
        world.step(origin_steps)
    origin = float(world.data.time)
    stamps: list[float] = []
    world.add_observer(lambda: stamps.append(float(world.data.time)), rate)
    world.step(3)  # the batches below start off the observer's grid
    world.command("kicker", "kick", mode="effort", value=EFFORT)
    for _ in range(BATCHES):
        world.step(batch)
    assert world.divergences >= BATCHES * batch // 2, (
        f"premise: batches replayed ({world.divergences})"
    )
    period = 1.0 / rate
    end = float(world.data.time)
    expected = origin + period * np.arange(1, int((end - origin) / period + 1e-6) + 1)
    on_grid = len(stamps) == len(expected) and np.allclose(stamps, expected, atol=GRID_TOL)
    assert on_grid, (
        f"calls {np.round(stamps, 4).tolist()} off the grid {np.round(expected, 4).tolist()}"
    )
