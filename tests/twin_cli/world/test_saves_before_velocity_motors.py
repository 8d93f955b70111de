"""A world file saved before joints had velocity motors still loads: written by twin at commit
7e6db57 (a two-wheel base whose ros2_control wheels have a 5 N m effort limit, commanded 2 and
1 rad/s, saved 0.3 s later). The world now gives each wheel a rotor (one qpos, dof, actuator and
body more), so the saved state gets those entries. Oracle: the file's own state and commands."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from twin_cli.world.savefile import load

SAVES = Path(__file__).parent / "saves"
NAME = "base_saved_before_velocity_motors"


@pytest.fixture
def save(tmp_path: Path) -> Path:
    """The file, naming the robot's URDF where this test put it."""
    robot = shutil.copy(SAVES / f"{NAME}.urdf", tmp_path / "bot.urdf")
    doc = json.loads((SAVES / f"{NAME}.json").read_text())
    doc["entities"][0]["source"] = str(robot)
    path = tmp_path / "world.json"
    path.write_text(json.dumps(doc))
    return path


def test_it_loads_with_the_saved_pose_and_the_wheels_go_on_at_their_commands(save: Path) -> None:
    doc = json.loads(save.read_text())
    saved_root = doc["state"][1:8]  # time, then the base's free joint (the first qpos)
    world = load(save)
    assert list(world.data.qpos[:7]) == pytest.approx(saved_root, abs=1e-12)
    world.step(500)
    speeds = {s.name: s.velocity for s in world.joint_states("bot")}
    assert speeds["wheel_left_joint"] == pytest.approx(2.0, rel=1e-3), speeds
    assert speeds["wheel_right_joint"] == pytest.approx(1.0, rel=1e-3), speeds
    assert not any("|" in name for name in speeds), "a rotor is listed"


def test_a_reset_of_the_loaded_world_returns_the_saved_spawn_state(save: Path) -> None:
    doc = json.loads(save.read_text())
    spawn = doc["entities"][0]["spawn_state"]["qpos"]
    world = load(save)
    world.reset()
    wheels = [s.position for s in world.joint_states("bot")]
    assert list(world.data.qpos[:7]) == pytest.approx(spawn[:7], abs=1e-12)
    assert wheels == pytest.approx(spawn[7:9], abs=1e-12)
