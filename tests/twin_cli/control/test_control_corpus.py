"""Every corpus robot, on the ground, driven 10 s by random commands in each of its modes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from corpus_registry import corpus_ids

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World
from twin_cli.world.joint_control import allowed_range, limits_of

HOLD_STEPS = 50  # 50 ms per random command at the 1 ms step
SECONDS = 10.0  # of sim time per robot and mode
# solo12's URDF gives 1000 N m (and 1000 rad/s) to legs of 7-150 g (its real motors: about
# 2.7 N m): 2e6 rad/s² reach the velocity limit in half a millisecond and throw the legs into
# their stops; MuJoCo raises BADQACC within 50 ms (effort, velocity) and 0.7 s (position) of
# random commands over the full ranges. Its position and velocity targets are drawn within 10 %
# of each range around its centre (measured, implicit integrator: peaks of 68 and 160 rad/s,
# no warning in 10 s on seeds 0-4 of `default_rng`), its efforts within 1 N m (0.001 of the
# range). At its real motors' 2.7 N m the efforts spin its legs to 400-750 rad/s and seeds 3
# and 5 of 0-5 diverge (at 2.45 s and 1.35 s); at 1 N m all six run the 10 s, under the
# world's implicitfast as under implicit.
RANGE_SCALE = {"solo12": 0.1}
EFFORT_SCALE = {"solo12": 0.001}


def _random_targets(world: World, name: str, mode: str, rng, scale: float) -> dict[str, float]:
    model, out = world.model, {}
    for state in world.joint_states(name):
        limits = limits_of(model, name, state.name)
        if mode not in limits.modes:
            continue
        j = model.joint(f"{name}/{state.name}").id
        a = [i for i in world.index_of(name).actuators if model.actuator_trnid[i][0] == j]
        if not a:
            continue
        effort = float(np.max(np.abs(model.actuator_ctrlrange[a[0]])))
        low, high = allowed_range(model, j, mode, limits, effort)
        if mode == "velocity" and not math.isfinite(high):
            low, high = -1.0, 1.0  # [rad/s] a joint without a velocity limit
        if mode == "position" and not math.isfinite(high):
            low, high = state.position - math.pi, state.position + math.pi
        centre, half = (low + high) / 2.0, (high - low) / 2.0 * scale
        low, high = centre - half, centre + half
        out[state.name] = float(rng.uniform(low, high))
    return out


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_on_the_ground_takes_random_commands_in_every_mode_without_warnings(
    robot_id: str, converted_corpus
) -> None:
    spec = converted_corpus(robot_id).spec
    for mode in ("position", "velocity", "effort"):
        world = World()
        world.spawn(SpawnRequest(spec.copy(), on_ground=True), name="robot")
        rng = np.random.default_rng(0)
        driven = 0
        for _ in range(round(SECONDS * 1000) // HOLD_STEPS):
            scales = EFFORT_SCALE if mode == "effort" else RANGE_SCALE
            targets = _random_targets(world, "robot", mode, rng, scales.get(robot_id, 1.0))
            if not targets:
                break
            world.command_joints("robot", targets, mode=mode)
            world.step(HOLD_STEPS)
            driven += 1
        if not driven:
            continue  # the robot's tags do not offer this mode
        warnings = {i: w.number for i, w in enumerate(world.data.warning) if w.number}
        assert warnings == {}, f"{robot_id} {mode}: MuJoCo warnings (index: count) {warnings}"
        assert world.divergences == 0, f"{robot_id} {mode}: {world.divergence_log}"
        assert np.isfinite(world.data.qpos).all(), f"{robot_id} {mode}: state"
        assert world.data.time == pytest.approx(SECONDS), f"{robot_id} {mode}: sim time"
