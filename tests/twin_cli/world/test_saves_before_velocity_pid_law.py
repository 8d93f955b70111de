"""A world file saved when a tag's velocity PID ran as an `intvelocity` still loads, state intact:
written by twin at commit 911a000 (an arm whose ros2_control `vel_joint` has no effort limit, so
an `intvelocity` of its own, commanded 1 rad/s, and a fan whose gz-sim JointController runs
force commands, p 0.5, commanded 3 rad/s; saved 0.5 s later). The fan's PID is now its law
p·(ω* − ω) on an activation that follows ctrl, in the slot its integral had, so every other
joint keeps its own saved activation; the arm's `vel_joint` now runs Gazebo's velocity motor,
unbounded as its joint is. Oracle: the file's own state and commands, and the law."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from old_saves import placed_save
from pid_law import pid_law

from twin_cli.world.savefile import load
from twin_cli.world.velocity_motors import RULE

NAME = "pid_saved_as_intvelocity"


@pytest.fixture
def save(tmp_path: Path) -> Path:
    """The file, naming the robots' URDFs where this test put them."""
    return placed_save(NAME, ("arm", "fan"), tmp_path)


def test_each_joint_goes_on_from_its_saved_state_under_its_command(save: Path) -> None:
    doc = json.loads(save.read_text())
    saved = dict(zip(("pos_joint", "vel_joint", "fan_joint"), doc["state"][1:4], strict=True))
    world = load(save)
    before = {s.name: s.position for e in ("arm", "rig") for s in world.joint_states(e)}
    assert before == pytest.approx(saved, abs=1e-12), "the saved positions"
    world.step(200)
    arm = {s.name: s for s in world.joint_states("arm")}
    assert arm["vel_joint"].position == pytest.approx(saved["vel_joint"] + 0.2, abs=1e-3)
    assert arm["vel_joint"].velocity == pytest.approx(1.0, rel=1e-3), "on its velocity motor"
    fan = {s.name: s for s in world.joint_states("rig")}["fan_joint"]
    assert fan.velocity == pytest.approx(3.0, rel=1e-3), "p·(ω* − ω) on 0.01 kg m², 0.2 s"
    row = world.joint_commands("rig")["fan_joint"]
    assert (row["kp"], row["kv"]) == (0.0, 0.5), f"the command row is the law's: {row}"
    arm_row = world.joint_commands("arm")["vel_joint"]
    assert (arm_row["kp"], arm_row["kv"], arm_row["rule"]) == (0.0, 0.0, RULE), arm_row
    assert arm_row["effort_limit"] is None, "no effort limit, as its URDF states none"


def test_a_reset_starts_the_fan_by_its_law_from_its_spawn_state(save: Path) -> None:
    world = load(save)
    world.reset()
    world.command_joints("rig", {"fan_joint": 3.0}, mode="velocity")
    world.step(40)
    fan = {s.name: s for s in world.joint_states("rig")}["fan_joint"]
    expected = pid_law(3.0, 0.5, 0.0, 0.04)
    assert fan.velocity == pytest.approx(expected, rel=0.05), f"{fan.velocity} rad/s at 40 ms"
