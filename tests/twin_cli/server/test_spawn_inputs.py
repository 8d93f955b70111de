"""What `twin spawn` sends besides the file: the shell's package variables and --repair-inertia.

The server converts, but a user expects `twin spawn` to resolve `$(find pkg)` as `twin convert`
does in the same shell, and to accept the option the refusal message names.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

WORLD = "inputs"
ROBOT = """<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find arm_parts)/base.xacro"/>
</robot>"""
BASE = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="base">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="{izz}" ixy="0" ixz="0" iyz="0"/>
  </inertial><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>"""


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    """A world server started with no package variables of its own."""
    with serve_world(tmp_path_factory.mktemp("rt"), WORLD) as served:
        yield served


def _robot(tmp_path, izz: str = "0.01"):
    parts = tmp_path / "share" / "arm_parts"
    parts.mkdir(parents=True)
    (parts / "base.xacro").write_text(BASE.format(izz=izz))
    robot = tmp_path / "robot" / "arm.urdf.xacro"  # not under the package: found only by path
    robot.parent.mkdir()
    robot.write_text(ROBOT)
    return robot, tmp_path / "share"


def _spawn(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess:
    clean = {k: v for k, v in os.environ.items() if k not in ("ROS_PACKAGE_PATH",)}
    return subprocess.run(
        [sys.executable, "-m", "twin_cli.cli.app", "spawn", *args, "--world", WORLD],
        capture_output=True,
        text=True,
        timeout=120,
        env={**clean, **env},
    )


def test_spawn_finds_packages_on_the_spawning_shells_ros_package_path(world, tmp_path):
    robot, share = _robot(tmp_path)
    refused = _spawn(str(robot), "--name", "a0", env={})
    assert refused.returncode == 2 and "arm_parts" in refused.stderr, refused.stderr
    assert "Traceback" not in refused.stderr
    done = _spawn(str(robot), "--name", "a1", env={"ROS_PACKAGE_PATH": str(share)})
    assert done.returncode == 0, done.stderr
    client, _ = world
    assert [e["name"] for e in client.entities()] == ["a1"]


def test_spawn_repairs_inertia_when_asked_as_its_refusal_says(world, tmp_path):
    robot, share = _robot(tmp_path, izz="0.05")  # izz > ixx + iyy: no physical body has it
    env = {"ROS_PACKAGE_PATH": str(share)}
    refused = _spawn(str(robot), "--name", "b0", env=env)
    assert refused.returncode == 2 and "--repair-inertia" in refused.stderr, refused.stderr
    done = _spawn(str(robot), "--name", "b1", "--repair-inertia", env=env)
    assert done.returncode == 0, done.stderr
    client, _ = world
    assert "b1" in [e["name"] for e in client.entities()]
    assert "b0" not in [e["name"] for e in client.entities()]
