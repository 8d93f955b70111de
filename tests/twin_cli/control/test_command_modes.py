"""Switching a live joint between the command interfaces its tags offer, as a ros2_control
controller switch does: real conversions, real physics, measured."""

from __future__ import annotations

import re

import pytest
from corpus_registry import CORPUS
from interface_models import PANDA_JOINTS, SEVERAL_INTERFACES, panda_arm
from models import two_wheel_bot, write_urdf

from twin_cli.control import follow_trajectory, tracking_report, trajectory_from_dict
from twin_cli.errors import InvalidRequestError, ModeNotOfferedError
from twin_cli.world import Pose, World, WorldSettings
from twin_cli.world.gravity_comp import ON

HOME = {"panda_joint4": -1.5, "panda_joint6": 1.5}  # the rest inside every joint's range
SPEED = 0.5  # [rad/s] velocity command
SPEED_TOLERANCE = 0.02  # velocity servo vs the commanded speed (measured worst 1.3 %: joint3)
REACHED = 1e-3  # [rad] position servo vs its target after SETTLE_STEPS
SETTLE_STEPS = 2500  # [ms] ≥ 6 time constants |Δ|/(0.95·v_max) for the ≤ 0.6 rad moves here


def _spawn_panda(tmp_path, gravity: bool = False) -> World:
    from converters import convert

    spec, _ = convert(write_urdf(tmp_path, panda_arm(), "panda.urdf"))
    world = World(WorldSettings() if gravity else WorldSettings(gravity=(0.0, 0.0, 0.0)))
    world.spawn(spec, name="panda", pose=Pose())
    return world


def _state(world: World, joint: str):
    return next(s for s in world.joint_states("panda") if s.name == joint)


def _actuator(world: World, joint: str) -> int:
    return world.model.actuator(f"panda/{joint}").id


def _check_velocity(world: World, joint: str) -> None:
    world.command_joints("panda", {joint: SPEED}, mode="velocity")
    link = int(world.model.joint(f"panda/{joint}").bodyid[0])
    assert world.model.body_gravcomp[link] != ON, f"{joint}: the position's gravcomp left"
    world.step(300)  # reach the speed
    start, t0 = _state(world, joint).position, world.data.time
    world.step(100)
    speed = (_state(world, joint).position - start) / (world.data.time - t0)
    assert speed == pytest.approx(SPEED, rel=SPEED_TOLERANCE), f"{joint}: {speed:.4f} rad/s"


def _check_effort(world: World, joint: str, effort: float) -> None:
    u = 0.25 * effort
    world.command_joints("panda", {joint: u}, mode="effort")
    a = _actuator(world, joint)
    low, high = world.model.actuator_forcerange[a]
    assert (low, high) == (0.0, u), f"{joint}: force range {low, high} (Gazebo's rule: [0, u])"
    world.step(1)
    dof = world.model.joint(f"panda/{joint}").dofadr[0]
    applied = world.data.actuator_force[a], world.data.qfrc_actuator[dof]
    assert applied == pytest.approx((u, u), abs=1e-9), f"{joint}: torque {applied} vs {u} N m"


def _check_position(world: World, joint: str, target: float, effort: float) -> None:
    world.command_joints("panda", {joint: target}, mode="position")
    a = _actuator(world, joint)
    assert tuple(world.model.actuator_forcerange[a]) == (-effort, effort), f"{joint}: range"
    world.step(SETTLE_STEPS)
    error = abs(_state(world, joint).position - target)
    assert error < REACHED, f"{joint}: {error:.2e} rad from its target after 2.5 s"


def _switch_every_mode(world: World) -> None:
    """Each arm joint of `panda` through every switch of the three modes: p→v, v→e, e→p,
    p→e, e→v, v→p, each measured as it acts."""
    home = {j: HOME.get(j, 0.0) for j in PANDA_JOINTS}
    world.command_joints("panda", home, mode="position")
    world.step(SETTLE_STEPS)
    for joint, (*_, effort) in PANDA_JOINTS.items():
        _check_velocity(world, joint)
        _check_effort(world, joint, effort)
        _check_position(world, joint, home[joint] + 0.3, effort)
        _check_effort(world, joint, effort)
        _check_velocity(world, joint)
        _check_position(world, joint, home[joint], effort)
    assert sum(w.number for w in world.data.warning) == 0, "MuJoCo warnings"


def test_panda_arm_joints_switch_between_all_three_modes_while_running(tmp_path):
    # Zero gravity: the switches, not the servos' response to the arm's weight, are measured.
    _switch_every_mode(_spawn_panda(tmp_path))


def test_a_switch_under_gravity_holds_where_the_joint_is_without_the_old_target(tmp_path):
    # A zero velocity holds under the arm's weight (the joint's friction bounded by its effort);
    # what the position servo held (its target, the gravity compensation) must not act.
    world = _spawn_panda(tmp_path, gravity=True)
    world.command_joints("panda", {j: HOME.get(j, 0.0) for j in PANDA_JOINTS}, mode="position")
    world.step(SETTLE_STEPS)  # the other joints hold the arm still, not flop under gravity
    world.command_joints("panda", {"panda_joint2": 0.5}, mode="position")
    link = int(world.model.joint("panda/panda_joint2").bodyid[0])
    assert world.model.body_gravcomp[link] == ON, "joint2 holds the arm with gravcomp"
    world.step(150)  # mid-move
    world.command_joints("panda", {"panda_joint2": 0.0}, mode="velocity")
    world.step(200)  # the hold, bounded by the effort, brakes the moving arm (~0.1 s measured)
    there = _state(world, "panda_joint2").position
    assert 0.01 < there < 0.45, f"the switch came mid-move: {there:.3f} rad"
    world.step(1000)
    state = _state(world, "panda_joint2")
    assert abs(state.position - there) < 5e-3, f"moved {state.position - there:+.4f} rad"
    assert abs(state.velocity) < 1e-3, state


def test_switching_a_followed_joint_stops_the_trajectory_and_keeps_the_new_command(tmp_path):
    world = _spawn_panda(tmp_path)
    names = ["panda_joint1", "panda_joint2", "panda_joint3"]
    points = [{"positions": [0.4, 0.4, 0.4], "time_from_start": 2.0}]
    follow_trajectory(
        world, "panda", trajectory_from_dict({"joint_names": names, "points": points})
    )
    world.step(500)
    _check_velocity(world, "panda_joint2")  # the follower must not write positions into it
    report = tracking_report(world, "panda")
    assert report is not None and not report["active"], "the switch ended the trajectory"
    command = world.joint_commands("panda")["panda_joint2"]
    assert (command["mode"], command["target"]) == ("velocity", SPEED), command
    held = world.joint_commands("panda")["panda_joint1"]
    assert held["mode"] == "position" and held["target"] < 0.4, "stopped where it was"


def test_a_mode_the_joint_does_not_offer_is_refused_naming_the_offered_ones(tmp_path):
    world = World()
    world.spawn(write_urdf(tmp_path, SEVERAL_INTERFACES), name="discs")
    before = world.model.actuator_gainprm.copy(), world.data.ctrl.copy()
    held = dict(world.commands())  # the joints' own servos hold them from load
    cases = [
        ("d1", "velocity", "its <transmission> tags offer only position; use --mode position"),
        ("d2", "position", "offer only velocity, effort; use --mode velocity or effort"),
    ]
    for joint, mode, words in cases:
        with pytest.raises(ModeNotOfferedError, match=re.escape(words)) as caught:
            world.command_joints("discs", {"d0": 0.1, joint: 0.1}, mode=mode)
        message = str(caught.value)
        assert f"joint [{joint}] of [discs]" in message, message
        assert f'<command_interface name="{mode}"/>' in message, "the fix names the tag"
    with pytest.raises(InvalidRequestError, match=re.escape("outside [-3, 3]")):
        world.command_joints("discs", {"d0": 3.5}, mode="position")  # the joint's range
    assert world.commands() == held, "a refused request changes no command"
    after = world.model.actuator_gainprm, world.data.ctrl
    assert (after[0] == before[0]).all() and (after[1] == before[1]).all()
    for joint, mode in (("d0", "effort"), ("d1", "position"), ("d2", "effort")):
        world.command_joints("discs", {joint: 0.1}, mode=mode)  # the offered ones work
    points = [{"positions": [0.1], "time_from_start": 1.0}]  # JTC claims position only
    with pytest.raises(InvalidRequestError, match=re.escape("[d2] of [discs]: its tags offer")):
        follow_trajectory(
            world, "discs", trajectory_from_dict({"joint_names": ["d2"], "points": points})
        )
    modes = {j: (c["mode"], c["modes"]) for j, c in world.joint_commands("discs").items()}
    assert modes == {
        "d0": ("effort", ["position", "velocity", "effort"]),
        "d1": ("position", ["position"]),
        "d2": ("effort", ["velocity", "effort"]),
    }, modes


def test_a_plugins_wheel_refuses_other_modes_without_suggesting_a_tag(tmp_path):
    # libgazebo_ros_diff_drive drives its wheels by velocity: a plugin, not a tag to extend.
    plugin = (
        '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>lj</left_joint>'
        "<right_joint>rj</right_joint><wheel_separation>0.2</wheel_separation>"
        "<wheel_diameter>0.1</wheel_diameter></plugin>"
    )
    world = World()
    world.spawn(write_urdf(tmp_path, two_wheel_bot(plugin)), name="bot", pose=Pose(z=1.0))
    with pytest.raises(ModeNotOfferedError) as caught:
        world.command_joints("bot", {"lj": 0.1}, mode="effort")
    message = str(caught.value)
    assert (
        "its gazebo_ros_diff_drive plugin offers only velocity; use --mode velocity" in message
    ), message
    assert "declare" not in message, message


@pytest.mark.skipif("franka_panda" not in CORPUS, reason="corpus: no franka_panda entry")
def test_corpus_franka_panda_offers_and_switches_every_mode_on_each_arm_joint(converted_corpus):
    world = World(WorldSettings(gravity=(0.0, 0.0, 0.0)))  # as the test-written arm above
    world.spawn(converted_corpus("franka_panda").spec, name="panda", pose=Pose())
    offered = {j: c["modes"] for j, c in world.joint_commands("panda").items()}
    for joint in PANDA_JOINTS:
        assert offered.get(joint) == ["position", "velocity", "effort"], (joint, offered)
    _switch_every_mode(world)


@pytest.mark.parametrize("effort", [10.0, 0.0])
def test_a_restore_gives_a_dropped_commands_motor_its_joints_full_effort(tmp_path, effort):
    """A restore to a state without a command releases its motor within the joint's effort
    limit, not the dropped command's (an effort command narrows the force range to its own u):
    a later position move then has the joint's whole effort and arrives."""
    world = _spawn_panda(tmp_path)
    joint = "panda_joint1"
    before, before_commands = world.snapshot(), dict(world.commands())
    full = world.joint_commands("panda")[joint]["effort_limit"]
    world.command_joints("panda", {joint: effort}, mode="effort")
    world.step(10)
    world.restore(before)
    assert world.commands() == before_commands, "the spawn's own holds, as they were"
    assert world.joint_commands("panda")[joint]["effort_limit"] == full
    world.command_joints("panda", {joint: 0.5}, mode="position")
    assert world.commands()[f"panda/{joint}"].effort == full
    world.step(SETTLE_STEPS)
    assert abs(_state(world, joint).position - 0.5) < REACHED
