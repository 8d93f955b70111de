"""At rest means at rest: corpus robots left on flat ground, and turtlebot3 after a drive, do not
creep. Oracle: a body at rest stays where it is (Gazebo's contacts hold it; MuJoCo's soft ones
used to let a turtlebot3 wander 0.48 m in 500 s and the humanoid slide 0.65 mm/s)."""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pytest
from corpus_registry import (
    CORPUS,
    NON_PHYSICAL_INERTIA,
    PACKAGES_ROOT,
    corpus_ids_expecting,
    package_paths,
)

from twin_cli.control import drive
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

SETTLE_S, WATCH_S = 2.0, 60.0
MOVED_M, TURNED_RAD = 1e-3, 1e-3
# Robots that do not stand still when left limp, with what they do in the 60 s (measured under
# the world's implicitfast integrator and elliptic friction cone). The limp legged robots creep
# where their splayed legs push their feet outwards: MuJoCo's soft friction rows give way under a
# steady tangential load at a rate set by their regulariser, which the elliptic cone keeps
# apart from the normal's (ODE's friction box would hold them); `impratio` 10 (stiffer friction
# rows) doubled hyq's creep, and MuJoCo's noslip pass (friction re-solved hard) made one robot's
# motion depend on another's spawn and a wheel overshoot its command by half. The IRB 2400, limp
# on its free base, swings its 0.5 kg wrist from its 257 kg links through the Coriolis forces
# implicitfast leaves explicit (under `implicit`: 0.05 mm, 0.008 mrad; held by its motors it
# stands still under both).
STILL_FALLING = {
    "hyq": "limp on its splayed legs: 6.97 mm, 13.5 mrad; its hip assembly 11.4 mm",
    "aliengo": "limp on its splayed legs: 0.67 mm, 2.74 mrad; a calf 3.04 mm",
    "solo12": "lies limp on its splayed 7-150 g legs: 0.037 mm, 3.43 mrad; a lower leg 3.95 mm",
    "booster_t1": "topples from standing: 58.6 mm, 0.80 rad; a hand 236 mm",
    "abb_irb2400_12_155": "limp wrist swung by explicit Coriolis forces: 0.025 mm, 0.004 mrad; "
    "its limp lever link_lever_b swings 6.1 mm",
    "ur5e": "held at home, its outstretched arm lies on its wrist: base edge and wrist carry "
    "2.1 N and 0.5 N sideways, under which the soft friction creeps 15 µm/s: 1.03 mm, 0.80 mrad",
}


def corpus_spawn_request(robot_id: str) -> SpawnRequest:
    """A corpus robot as `twin spawn --on-ground` takes it (the options its files need)."""
    robot = CORPUS[robot_id]
    return SpawnRequest(
        str(PACKAGES_ROOT / robot["entry"]),
        package_paths={k: str(v) for k, v in package_paths(robot).items()},
        args=robot["xacro_args"],
        repair_inertia=robot_id in NON_PHYSICAL_INERTIA,
        on_ground=True,
    )


class Drift(NamedTuple):
    """What an entity did over WATCH_S: its root's move [m] and turn [rad], and the link that
    moved most, with how far [m]."""

    moved: float
    turned: float
    link: str
    link_moved: float

    def __str__(self) -> str:
        return (
            f"root moved {self.moved * 1e3:.4f} mm, turned {self.turned * 1e3:.4f} mrad; "
            f"link '{self.link}' moved {self.link_moved * 1e3:.4f} mm in {WATCH_S} s"
        )

    def still(self) -> bool:
        return self.moved < MOVED_M and self.turned < TURNED_RAD and self.link_moved < MOVED_M


def _link_positions(world: World, name: str) -> dict[str, np.ndarray]:
    model, data = world.model, world.data
    prefix = f"{name}/"
    return {
        model.body(b).name.removeprefix(prefix): data.xpos[b].copy()
        for b in range(model.nbody)
        if model.body(b).name.startswith(prefix)
    }


def _drift(world: World, name: str) -> Drift:
    """Every link is followed, not only the root: a drooping limb of a still base counts."""
    p0, links0 = world.get_pose(name), _link_positions(world, name)
    world.step(round(WATCH_S / world.model.opt.timestep))
    p1, links1 = world.get_pose(name), _link_positions(world, name)
    moved = math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z))
    turned = max(
        abs(p1.roll - p0.roll),
        abs(p1.pitch - p0.pitch),
        abs(math.remainder(p1.yaw - p0.yaw, 2 * math.pi)),
    )
    link_moved = {k: float(np.linalg.norm(links1[k] - x)) for k, x in links0.items()}
    link = max(link_moved, key=link_moved.__getitem__)
    return Drift(moved, turned, link, link_moved[link])


@pytest.mark.parametrize(
    "robot_id",
    corpus_ids_expecting(STILL_FALLING),
)
def test_a_corpus_robot_left_on_the_ground_stays_put(robot_id: str) -> None:
    world = World()
    world.spawn(corpus_spawn_request(robot_id), name="r")
    world.step(round(SETTLE_S / world.model.opt.timestep))
    drift = _drift(world, "r")
    assert drift.still(), f"{robot_id}: {drift}"


@pytest.mark.skipif("abb_irb2400_12_155" not in CORPUS, reason="corpus: no abb_irb2400_12_155")
def test_the_limp_irb2400_stands_still_when_its_motors_hold_it() -> None:
    """The IRB 2400 that creeps limp (STILL_FALLING) stands still with every joint held at
    speed 0 from its spawn posture (its six motors; its passive lever joints stay limp): the
    creep is its swinging wrist, not its contacts."""
    world = World()
    world.spawn(corpus_spawn_request("abb_irb2400_12_155"), name="r")
    world.command_joints("r", {f"joint_{k}": 0.0 for k in range(1, 7)}, mode="velocity")
    world.step(round(SETTLE_S / world.model.opt.timestep))
    drift = _drift(world, "r")
    assert drift.still(), f"held: {drift}"


@pytest.mark.skipif("turtlebot3_burger" not in CORPUS, reason="corpus: no turtlebot3_burger")
def test_turtlebot3_stands_still_after_a_drive() -> None:
    """Its wheels commanded back to 0 hold it: before, they kept turning at ±0.023 rad/s."""
    world = World()
    world.spawn(corpus_spawn_request("turtlebot3_burger"), name="tb3")
    world.step(300)
    drive(world, "tb3", 0.2, 0.5, 5.0)
    world.step(6000 + round(SETTLE_S / world.model.opt.timestep))
    drift = _drift(world, "tb3")
    assert drift.still(), str(drift)
    speeds = [abs(j.velocity) for j in world.joint_states("tb3")]
    assert max(speeds) < 1e-4, f"wheels still turn at {speeds} rad/s"


def _moved_on_a_slope(world: World, name: str) -> float:
    """Tilts gravity 5° along +x (a slope down +x) and returns how far `name` moves [m] in the
    10 s after 5 s on it."""
    slope = math.radians(5.0)
    world.set_gravity((9.81 * math.sin(slope), 0.0, -9.81 * math.cos(slope)))
    world.step(5000)
    p0 = world.get_pose(name)
    world.step(10000)
    p1 = world.get_pose(name)
    return math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z))


@pytest.mark.skipif("turtlebot3_burger" not in CORPUS, reason="corpus: no turtlebot3_burger")
def test_turtlebot3_stopped_on_a_slope_holds() -> None:
    """Driven, stopped, then on a 5° slope (gravity tilted along its heading): its wheels' zero
    velocity servos hold it. They crept 0.64 mm in these 10 s while each chattering swing of a
    light wheel back towards its reference leaked the integral that holds the load."""
    world = World()
    world.spawn(corpus_spawn_request("turtlebot3_burger"), name="tb3")
    world.step(300)
    drive(world, "tb3", 0.2, 0.0, 1.0)
    world.step(2000)
    moved = _moved_on_a_slope(world, "tb3")
    assert moved < 2e-4, f"moved {moved * 1e3:.3f} mm in 10 s on a 5° slope"


@pytest.mark.skipif("turtlebot3_burger" not in CORPUS, reason="corpus: no turtlebot3_burger")
def test_turtlebot3_driven_then_reset_holds_on_a_slope() -> None:
    """A reset takes the clock back: the leak window of its stopped wheels restarts there instead
    of staying open until the clock passes the old stop (0.64 mm in these 10 s)."""
    world = World()
    world.spawn(corpus_spawn_request("turtlebot3_burger"), name="tb3")
    world.step(27000)  # a stop late on the clock: its window would stay open after the reset
    drive(world, "tb3", 0.2, 0.0, 1.0)
    world.step(3000)
    world.reset()
    world.step(300)
    moved = _moved_on_a_slope(world, "tb3")
    assert moved < 2e-4, f"moved {moved * 1e3:.3f} mm in 10 s on a 5° slope after a reset"
