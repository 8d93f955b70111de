"""Sleeping of resting robots: humanoids standing on their servos fall asleep, wake
when pushed or commanded, and rest where a world without sleeping puts them. Oracles: MuJoCo's
own sleep state (`tree_asleep`, `ntree_awake`), and the same world stepped without sleeping."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

import scenarios
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

ROBOTS = 4
DROP = 0.3  # [m] each humanoid starts this far above its resting height
SETTLE_S = 1.0  # [s] sim time by which every dropped humanoid is asleep (0.5 s measured)
TOLERANCE = 0.01  # [m/s] a landed humanoid chatters at 2-6 mm/s on Gazebo's stiff contacts
POSE_TOL = 1e-3  # [m, rad] resting qpos, sleeping vs awake world (5e-4 measured)
PUSH_TOL = 0.005  # [m] a woken robot's travel vs one that never slept (0.5 mm measured)
COMMAND_TOL = 1e-3  # [rad] joint angle reached after a command, sleeping vs awake world


def _dropped(sleep: bool) -> World:
    """ROBOTS humanoids holding every joint at 0, dropped DROP above the ground."""
    world = World()
    world.set_engine(sleep=sleep, sleep_tolerance=TOLERANCE)
    poses = [Pose(x=1.5 * k, z=1.3) for k in range(ROBOTS)]
    for r in world.spawn_batch(
        SpawnRequest(scenarios.HUMANOID, on_ground=True), base="h", poses=poses
    ):
        for joint in world.joint_states(r.name):
            world.command(r.name, joint.name, mode="position", value=0.0)
        p = world.get_pose(r.name)
        world.set_pose(r.name, Pose(x=p.x, y=p.y, z=p.z + DROP))
    return world


@pytest.fixture
def worlds() -> dict[bool, World]:
    worlds = {sleep: _dropped(sleep) for sleep in (False, True)}
    for world in worlds.values():
        world.step(round(SETTLE_S / world.model.opt.timestep))
    return worlds


def test_dropped_humanoids_fall_asleep_and_rest_where_awake_ones_do(worlds):
    asleep, awake = worlds[True], worlds[False]
    assert asleep.data.ntree_awake == 0, list(asleep.data.tree_asleep)
    assert (asleep.data.tree_asleep >= 0).all()
    assert awake.data.ntree_awake == ROBOTS  # the oracle world never sleeps
    assert (asleep.data.qvel == 0).all()  # asleep means held, not integrated
    heights = [asleep.get_pose(f"h_{k}").z for k in range(ROBOTS)]
    assert min(heights) > 0.5, heights  # standing, not fallen
    assert np.abs(asleep.data.qpos - awake.data.qpos).max() < POSE_TOL


def test_a_pushed_robot_wakes_alone_and_moves_as_an_awake_one(worlds):
    travel = {}
    for sleep, world in worlds.items():
        start = world.get_pose("h_1")
        world.push("h_1", (0.0, 100.0, 0.0), duration=0.3)
        world.step(1)
        if sleep:  # only the pushed robot's island wakes; the others stay asleep
            assert world.data.ntree_awake == 1
        world.step(499)
        end = world.get_pose("h_1")
        travel[sleep] = np.array([end.x - start.x, end.y - start.y, end.z - start.z])
    assert travel[False][1] > 0.2, travel  # the push slid it 0.25 m
    assert np.abs(travel[True] - travel[False]).max() < PUSH_TOL, travel


def test_a_commanded_robot_wakes_and_its_joint_follows(worlds):
    reached = {}
    for sleep, world in worlds.items():
        if sleep:
            assert world.data.tree_asleep[_tree(world, "h_2")] >= 0  # h_2 sleeps before
        world.command("h_2", "left_shoulder", mode="position", value=0.5)
        world.step(1)
        assert world.data.tree_asleep[_tree(world, "h_2")] < 0  # the command woke it
        world.step(499)
        states = {j.name: j.position for j in world.joint_states("h_2")}
        reached[sleep] = states["left_shoulder"]
    assert reached[False] > 0.4, reached
    assert reached[True] == pytest.approx(reached[False], abs=COMMAND_TOL)


def _tree(world: World, name: str) -> int:
    """The kinematic tree of entity `name` (a humanoid is one tree)."""
    model = world.model
    (tree,) = {
        int(model.body_treeid[b])
        for b in range(model.nbody)
        if model.body(b).name.startswith(f"{name}/")
    }
    return tree


def test_a_base_with_one_wheel_driven_stays_awake_and_sleeps_once_both_stop(tmp_path):
    """A velocity command other than 0 keeps its robot awake until the next command, even when
    the other wheel on the same robot is told to stop after it (a zero velocity lets a robot
    sleep: its joints' friction holds it); with both stopped the base falls asleep."""
    import drive_models as dm

    path = tmp_path / "base.urdf"
    path.write_text(dm.two_wheel_base(""))
    world = World()
    world.set_engine(sleep=True, sleep_tolerance=TOLERANCE)
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.command("base", "wheel_left_joint", mode="velocity", value=2.0)
    world.command("base", "wheel_right_joint", mode="velocity", value=0.0)
    world.step(1000)
    tree = _tree(world, "base")
    assert world.data.tree_asleep[tree] < 0, "asleep while a wheel is driven"
    never = int(mujoco.mjtSleepPolicy.mjSLEEP_AUTO_NEVER)
    assert world.model.tree_sleep_policy[tree] == never, "may sleep while a wheel is driven"
    # One wheel at 2 rad/s for 1 s turns the base (measured -0.33 rad): it moved while awake.
    assert abs(world.get_pose("base").yaw) > 0.2, "the driven wheel did not turn the base"
    world.command("base", "wheel_left_joint", mode="velocity", value=0.0)
    world.step(round(SETTLE_S / world.model.opt.timestep))
    assert world.data.tree_asleep[tree] >= 0, "still awake with both wheels stopped"
