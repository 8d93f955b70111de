"""What an active diff drive costs the loop, in one run.

One world holds turtlebot3 (from the corpus) driving in circles and the bundled humanoid. Plain
windows step it with the diff-drive controller stopped (its last wheel targets stay in force);
driven windows with the controller running at its plugin's update rate, each starting with a new
command (ω reversed), so a ramp and the hold are both in every driven window. Target:
driven throughput ≥ 0.95 of plain (median of alternating pairs of 2 s windows). A ratio.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

from twin_cli.control import controller_of, drive
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

ROOT = Path(__file__).parents[1]
HUMANOID = ROOT / "scenarios" / "robots" / "humanoid.urdf.xacro"
PACKAGES = ROOT.parent / "shared" / "corpus" / "packages"
TURTLEBOT = PACKAGES / "turtlebot3_description" / "urdf" / "turtlebot3_burger.urdf.xacro"
STEPS, BATCH, PAIRS = 2000, 500, 7
TARGETS = {"driven_vs_plain": 0.95}
V, W = 0.2, 0.5  # [m/s], [rad/s]


def _world() -> World:
    world = World()
    paths = {"turtlebot3_description": str(PACKAGES / "turtlebot3_description")}
    world.spawn(SpawnRequest(str(TURTLEBOT), package_paths=paths, on_ground=True), name="tb3")
    world.spawn(SpawnRequest(HUMANOID, on_ground=True), name="h", pose=Pose(x=3.0))
    world.step(300)
    return world


def _throughput(world: World) -> float:
    start = time.perf_counter()
    for _ in range(STEPS // BATCH):
        world.step(BATCH)
    return STEPS / (time.perf_counter() - start)


def run() -> dict:
    """Steps per second with the controller stopped and running, and their ratio (median of
    alternating pairs); the wheel targets it wrote stay in force while it is stopped."""
    if not TURTLEBOT.is_file():
        return {"skipped": f"corpus robot not found at {TURTLEBOT}"}
    world = _world()
    drive(world, "tb3", V, W)
    world.step(1000)  # past the ramp: the controller holds the command at the plugin's rate
    controller = controller_of(world, "tb3")
    ratios, rates = [], []
    for k in range(PAIRS):
        controller.stop()
        plain = _throughput(world)
        controller.resume()
        drive(world, "tb3", V, W if k % 2 else -W)  # a new command: a ramp in every window
        driven = _throughput(world)
        ratios.append(driven / plain)
        rates.append((plain, driven))
    return {
        "controller_rate_hz": controller.rate,
        "plain_steps_per_s": statistics.median(r[0] for r in rates),
        "driven_steps_per_s": statistics.median(r[1] for r in rates),
        "driven_vs_plain": statistics.median(ratios),
        "targets": TARGETS,
    }
