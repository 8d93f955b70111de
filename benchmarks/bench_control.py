"""What Gazebo's limits and an active trajectory cost the loop, as ratios in one run.

Copies of the bundled humanoid float at zero gravity (no contacts) and step the same sim time in
alternating rounds:
- limits: every joint in effort mode under Gazebo's velocity rule (a velocity servo with an
  asymmetric force range per joint, evaluated by mj_step) against the same efforts on plain
  motors (no velocity rule), each window from the same saved state;
- trajectory: every joint following a trajectory at 100 Hz (the follower runs as a world
  observer: the batches split every 10 steps and Python writes the next reference) against a
  copy holding a position command.
Target: limits ≥ 0.95 of plain; the trajectory's ratio is reported.
"""

from __future__ import annotations

import math
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from twin_cli.control import follow_trajectory, trajectory_from_dict
from twin_cli.world import Pose, World, WorldSettings
from twin_cli.world.running import STATE

HUMANOID = Path(__file__).parents[1] / "scenarios" / "robots" / "humanoid.urdf.xacro"
STEPS = 1000  # per window: 1 s of sim time
ROUNDS = 7
TARGETS = {"limits_vs_plain": 0.95}


def _world() -> World:
    world = World(WorldSettings(gravity=(0.0, 0.0, 0.0)))
    world.spawn(HUMANOID, name="h", pose=Pose(z=3.0))
    return world


def _rows(world: World) -> list[dict]:
    from twin_cli.world.driving import joint_commands

    with world.lock:
        return [{"name": n, **r} for n, r in joint_commands(world, "h").items()]


def _efforts(world: World, rule: bool) -> None:
    """Every joint in effort mode at 5 % of its limit, with or without the velocity rule."""
    from twin_cli.world import actuation

    rows = _rows(world)
    world.command_joints(
        "h", {r["name"]: 0.05 * (r["effort_limit"] or 1.0) for r in rows}, mode="effort"
    )
    if not rule:  # the same efforts on plain motors (no velocity rule)
        with world.lock:
            for key, cmd in list(world.commands().items()):
                plain = replace(cmd, velocity_limit=math.inf)
                a = world.model.actuator(key).id
                actuation.apply_command(world.model, world.data, a, plain)
                world._state.commands[key] = plain


def _trajectory(world: World, follow: bool) -> None:
    """Every joint about mid-range: held there, or following ±10 % of its half-range at 1 Hz."""
    names = [r["name"] for r in _rows(world)]
    ranges = [world.model.joint(f"h/{n}").range for n in names]
    middle = {n: (lo + hi) / 2 for n, (lo, hi) in zip(names, ranges, strict=True)}
    if not follow:
        world.command_joints("h", middle, mode="position")
        return
    points = [
        {
            "positions": [(lo + hi) / 2 + 0.1 * (hi - lo) / 2 * (-1) ** k for lo, hi in ranges],
            "time_from_start": 0.5 * k,
        }
        for k in range(1, 8 * ROUNDS + 4)
    ]
    follow_trajectory(world, "h", trajectory_from_dict({"joint_names": names, "points": points}))


def _window(world: World, inside: list[float] | None = None) -> float:
    """Steps/s over STEPS steps; appends to `inside` the µs per step spent in `mj_step`."""
    stepping, start = world.stepping_time, time.perf_counter()
    world.step(STEPS)
    wall = time.perf_counter() - start
    if inside is not None:
        inside.append((world.stepping_time - stepping) / STEPS * 1e6)
    return STEPS / wall


def _pair(world: World, set_up, rounds: int) -> tuple[list[float], list[float]]:  # noqa: ANN001
    """Rates without and with the feature, each window from the same saved state."""
    import mujoco

    state = np.empty(mujoco.mj_stateSize(world.model, STATE))
    mujoco.mj_getState(world.model, world.data, state, STATE)
    without, with_ = [], []
    for _ in range(rounds):
        for flag, out in ((False, without), (True, with_)):
            mujoco.mj_setState(world.model, world.data, state, STATE)
            set_up(world, flag)
            out.append(_window(world))
    return without, with_


def run() -> dict:
    limits_world = _world()
    plain, limits = _pair(limits_world, _efforts, ROUNDS)
    held_world, follow_world = _world(), _world()
    _trajectory(held_world, False)
    _trajectory(follow_world, True)
    held, followed, held_mj, followed_mj = [], [], [], []
    for _ in range(ROUNDS):
        held.append(_window(held_world, held_mj))
        followed.append(_window(follow_world, followed_mj))
    median = statistics.median
    return {
        "steps_per_s": {
            "plain_efforts": round(median(plain)),
            "efforts_with_velocity_rule": round(median(limits)),
            "position_hold": round(median(held)),
            "trajectory_100hz": round(median(followed)),
        },
        "limits_vs_plain": round(median(limits) / median(plain), 3),
        "trajectory_vs_hold": round(median(followed) / median(held), 3),
        # Where the difference goes: mj_step itself is slower on moving joints (the servos track
        # a moving target), the rest of a step's wall time is the follower's 100 Hz Python.
        "us_per_step": {
            "hold_in_mj_step": round(median(held_mj), 2),
            "hold_total": round(1e6 / median(held), 2),
            "trajectory_in_mj_step": round(median(followed_mj), 2),
            "trajectory_total": round(1e6 / median(followed), 2),
        },
        "targets": TARGETS,
        "warnings": sum(
            w.number for m in (limits_world, held_world, follow_world) for w in m.data.warning
        ),
    }
