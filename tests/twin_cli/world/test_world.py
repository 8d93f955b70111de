"""World API: entity queries, errors, physics settings, run control, divergence, save/load."""

from __future__ import annotations

import json
import math

import mujoco
import numpy as np
import pytest
from models import mjcf_arm, mjcf_ball, mjcf_box, mjcf_stiff_spring
from world_helpers import full_state, spec_of

import twin_cli.world.engine as world_module
from twin_cli.errors import (
    EntityNotFoundError,
    InvalidRequestError,
    PartNotFoundError,
    WorldFileError,
)
from twin_cli.world import Pose, World, WorldSettings, savefile


def test_public_names_exist():
    for name in world_module.__all__:
        assert hasattr(world_module, name), f"twin_cli.world.engine.__all__ names missing {name}"


def test_default_world_is_gazebos_empty_world():
    world = World()
    physics = world.physics()
    assert (physics["timestep"], physics["rate"], physics["iterations"]) == (0.001, 1000.0, 50)
    assert physics["target_factor"] == 1.0, "1 ms at 1000 Hz is real time"
    assert world.gravity() == (0.0, 0.0, -9.81), "gravity"
    ground = world.model.geom("ground")
    assert ground.friction[0] == 100.0, "Gazebo ground μ"
    assert world.model.nlight == 1, "a sun"
    assert {"sor", "erp", "cfm"} <= set(physics["not_applicable"]), "ODE-only fields"


def test_pose_round_trips_between_rpy_and_quaternion():
    pose = Pose(1.0, 2.0, 3.0, roll=0.3, pitch=-0.4, yaw=2.5)
    back = Pose.from_quat(1.0, 2.0, 3.0, pose.quat())
    assert list(back.to_dict().values()) == pytest.approx(list(pose.to_dict().values())), "rpy"
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, np.array(pose.quat()))
    cr, sr, cp, sp = math.cos(0.3), math.sin(0.3), math.cos(-0.4), math.sin(-0.4)
    cy, sy = math.cos(2.5), math.sin(2.5)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    assert np.allclose(mat.reshape(3, 3), rz @ ry @ rx, atol=1e-12), "extrinsic X-Y-Z = Rz Ry Rx"


def test_entity_queries_report_pose_joints_and_links():
    world = World()
    world.spawn(spec_of(mjcf_arm(-1.0, 1.0, 5.0)), pose=Pose(x=1.0))
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    info = {e.name: e for e in world.entities()}
    assert info["arm"].n_joints == 1 and info["ball"].n_joints == 0, "free joint not counted"
    assert info["ball"].position == (0.0, 0.0, 2.0), "ball position"
    assert [j.name for j in world.joint_states("arm")] == ["shoulder"], "joint names unprefixed"
    links = world.link_poses("arm")
    assert set(links) == {"base", "link"}, "links unprefixed"
    assert (links["link"].x, links["link"].z) == pytest.approx((1.0, 1.0)), "link at spawn pose"
    world.set_pose("ball", Pose(x=-1.0, z=0.5, yaw=1.0))
    assert world.get_pose("ball") == pytest.approx(Pose(x=-1.0, z=0.5, yaw=1.0)), "teleported"
    world.set_pose("arm", Pose(x=2.0))
    assert world.link_poses("arm")["link"].x == pytest.approx(2.0), "fixed base moved"


def test_errors_name_the_subject_and_the_fix():
    world = World()
    world.spawn(spec_of(mjcf_arm(-1.0, 1.0, 5.0)))
    with pytest.raises(EntityNotFoundError, match=r"\[robot\].*arm"):
        world.get_pose("robot")
    with pytest.raises(PartNotFoundError, match=r"\[elbow\].*shoulder"):
        world.command("arm", "elbow", mode="position", value=0.0)
    with pytest.raises(InvalidRequestError, match="position, velocity, effort"):
        world.command("arm", "shoulder", mode="torque", value=0.0)
    with pytest.raises(PartNotFoundError, match=r"link \[hand\].*base, link"):
        world.push("arm", force=(1, 0, 0), link="hand")
    with pytest.raises(InvalidRequestError, match="3 finite numbers"):
        world.set_gravity((0.0, float("nan"), 0.0))
    with pytest.raises(InvalidRequestError, match="newton, cg, pgs"):
        world.set_physics(solver="quick")
    with pytest.raises(InvalidRequestError, match="duration"):
        world.push("arm", force=(1, 0, 0), duration=0.0)


def test_set_physics_changes_model_and_survives_a_spawn():
    world = World()
    result = world.set_physics(timestep=0.002, rate=0, iterations=20, solver="cg", integrator="rk4")
    assert (result["timestep"], result["rate"], result["target_factor"]) == (0.002, 0, None)
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=1.0))
    opt = world.model.opt
    assert (opt.timestep, opt.iterations) == (0.002, 20), "timestep and iterations compiled in"
    assert opt.solver == mujoco.mjtSolver.mjSOL_CG, "solver"
    assert opt.integrator == mujoco.mjtIntegrator.mjINT_RK4, "integrator"


def test_step_while_paused_and_reset_to_spawn_state():
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=2.0))
    spawn_state = full_state(world)
    world.pause()
    world.step(300)
    stats = world.stats()
    assert stats.paused and stats.iterations == 300, "stepping works while paused"
    assert stats.sim_time == pytest.approx(0.3), "sim time"
    world.reset(time_only=True)
    assert world.stats().sim_time == 0.0 and world.get_pose("ball").z < 2.0, "only time reset"
    world.reset()
    assert np.array_equal(full_state(world), spawn_state), "full reset = spawn state, time 0"


def test_reset_clears_joint_commands():
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(spec_of(mjcf_arm(-1.0, 1.0, 5.0)))
    world.command("arm", "shoulder", mode="position", value=0.5)
    world.reset()
    world.step(500)
    assert world.joint_states("arm")[0].position == 0.0, "no servo after reset"


def test_diverging_entity_is_reset_and_counted_while_the_others_keep_running():
    world = World(WorldSettings(integrator="euler"))
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=5.0))
    reference = World(WorldSettings(integrator="euler"))
    reference.spawn(spec_of(mjcf_ball()), pose=Pose(z=5.0))
    world.spawn(spec_of(mjcf_stiff_spring()), pose=Pose(x=3.0))
    for w in (world, reference):
        w.step(200)
    assert world.divergences >= 1, "the stiff spring diverged and was counted"
    assert world.divergence_log[0].entity == "spring", "the offending entity is named"
    ball = world.data.qpos[world.index_of("ball").qpos]
    assert np.allclose(ball, reference.data.qpos, atol=1e-12), "the ball kept falling"
    assert np.all(np.isfinite(world.data.qpos)), "state is finite"
    assert any("unstable" in w for w in world.mujoco_warnings), "MuJoCo's warning text is kept"


def test_nan_state_resets_only_the_offending_entity():
    world = World()
    world.spawn(spec_of(mjcf_ball()), pose=Pose(z=5.0))
    world.spawn(spec_of(mjcf_box()), pose=Pose(x=2.0, z=1.0))
    world.step(10)
    world.data.qvel[world.index_of("box").dofs[0]] = np.nan
    z_before = world.get_pose("ball").z
    world.step(10)
    assert world.divergences == 1, "one divergence"
    box = world.get_pose("box")
    fall_9_steps = 0.5 * 9.81 * 0.009 * 0.010  # reset at step 1, then falls 9 steps (Euler)
    assert box.x == 2.0 and box.z == pytest.approx(1.0 - fall_9_steps, abs=1e-9), f"box {box}"
    assert world.get_pose("ball").z < z_before, "ball kept falling"


def test_save_load_and_continue_gives_the_same_trajectory(tmp_path):
    path = tmp_path / "world.json"
    (tmp_path / "ball.xml").write_text(mjcf_ball())
    (tmp_path / "arm.xml").write_text(mjcf_arm(-1.0, 1.0, 5.0))
    world = World()
    world.spawn(tmp_path / "ball.xml", pose=Pose(z=1.0))
    world.spawn(tmp_path / "arm.xml", pose=Pose(x=1.0))
    world.command("arm", "shoulder", mode="position", value=0.4)
    world.push("ball", force=(4.0, 0.0, 0.0), duration=0.3)
    world.step(123)
    savefile.save(world, path)
    assert not list(tmp_path.glob(".world.json.*")), "no temporary file left"
    loaded = savefile.load(path)
    world.step(700), loaded.step(700)
    assert np.array_equal(full_state(loaded), full_state(world)), "same trajectory after load"
    assert loaded.stats().iterations == world.stats().iterations == 823, "iterations kept"


def test_save_load_of_mjspec_sources_continues_within_rounding(tmp_path):
    # An MjSpec source is saved as MJCF text (MjSpec.to_xml), which rounds floats: the loaded
    # model's masses differ in the last digits, so the trajectory matches closely, not bitwise.
    world = World()
    world.spawn(spec_of(mjcf_arm(-1.0, 1.0, 5.0)), pose=Pose(x=1.0))
    world.command("arm", "shoulder", mode="position", value=0.4)
    world.step(100)
    savefile.save(world, tmp_path / "world.json")
    loaded = savefile.load(tmp_path / "world.json")
    world.step(500), loaded.step(500)
    gap = np.max(np.abs(full_state(loaded) - full_state(world)))
    assert gap < 1e-9, f"state gap {gap:.3g} after 0.5 s (MJCF text rounding)"


def test_loading_a_bad_file_says_what_is_wrong(tmp_path):
    path = tmp_path / "notes.json"
    path.write_text(json.dumps({"hello": 1}))
    with pytest.raises(WorldFileError, match="not a twin world file"):
        savefile.load(path)
    with pytest.raises(WorldFileError, match="cannot read"):
        savefile.load(tmp_path / "missing.json")
