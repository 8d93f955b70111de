"""`twin drive`, `twin odom` and `twin command` as a user types them, on bases whose drives are
not diff drives, against a real (paused) world server: an Ackermann car takes a steering angle,
a curvature or a yaw rate; odometry names the plugin's frames; an option a base's drive does not
take, a base without a drive, and the fix that error names (run here as printed)."""

from __future__ import annotations

import json
import math
import re
import shlex
import subprocess
from pathlib import Path

import drive_models as dm
import pytest
from cli_world import twin_in, twin_ok

WORLD_NAME = "drive_families_cli"
ACKERMANN = (
    '<plugin name="ack" filename="libgazebo_ros_ackermann_drive.so"><front_left_joint>'
    "front_left_joint</front_left_joint><front_right_joint>front_right_joint</front_right_joint>"
    "<rear_left_joint>rear_left_joint</rear_left_joint><rear_right_joint>rear_right_joint"
    "</rear_right_joint><left_steering_joint>left_steering_joint</left_steering_joint>"
    "<right_steering_joint>right_steering_joint</right_steering_joint><max_steer>0.6</max_steer>"
    "<odometry_frame>odom_car</odometry_frame><robot_base_frame>base_link</robot_base_frame>"
    "</plugin>"
)
KOBUKI = (
    '<plugin name="kobuki_controller" filename="libgazebo_ros_kobuki.so">'
    "<wheel_left_joint_name>wheel_left_joint</wheel_left_joint_name><wheel_right_joint_name>"
    "wheel_right_joint</wheel_right_joint_name><wheel_separation>0.3</wheel_separation>"
    "<wheel_diameter>0.1</wheel_diameter></plugin>"
)
JTC = (
    '<plugin filename="gz-sim-joint-trajectory-controller-system" '
    'name="gz::sim::systems::JointTrajectoryController"><joint_name>shoulder</joint_name>'
    "<joint_name>elbow</joint_name><position_p_gain>200</position_p_gain><position_p_gain>100"
    "</position_p_gain><position_d_gain>12</position_d_gain><position_d_gain>4"
    "</position_d_gain></plugin>"
)
BOX = '<sdf version="1.6"><model name="box"><link name="l"><collision name="c"><geometry><box>'
BOX += "<size>0.2 0.2 0.2</size></box></geometry></collision></link></model></sdf>"


def _twin(runtime: Path, *args: str) -> subprocess.CompletedProcess:
    return twin_in(runtime, WORLD_NAME, *args)


def _ok(runtime: Path, *args: str) -> str:
    return twin_ok(runtime, WORLD_NAME, *args)


@pytest.fixture(scope="module")
def served(tmp_path_factory, serve_world):
    """A paused world with an Ackermann car, a vendor diff-drive base, a base whose wheels no
    plugin drives, an arm a JointTrajectoryController drives, and a box."""
    root = tmp_path_factory.mktemp("drive_families_cli")
    robots = {
        "car": dm.ackermann_car(ACKERMANN),
        "kobuki": dm.two_wheel_base(KOBUKI),
        "cart": dm.two_wheel_base(""),
    }
    with serve_world(root, WORLD_NAME, "--paused"):
        for i, (name, text) in enumerate(robots.items()):
            path = root / f"{name}.urdf"
            path.write_text(text)
            _ok(root, "spawn", str(path), "--name", name, "-y", str(2.0 * i), "--on-ground")
        _ok(root, "spawn", "--xml", BOX, "--name", "box", "-x", "3", "-z", "0.1")
        (root / "arm.urdf").write_text(dm.arm_urdf(JTC))
        _ok(root, "spawn", str(root / "arm.urdf"), "--name", "arm", "-x", "-3")
        _ok(root, "step", "300")
        yield root


@pytest.mark.parametrize(
    ("option", "value", "phi"),
    [
        ("--steering", "0.3", 0.3),
        ("--curvature", "1.0", math.atan(dm.WHEEL_BASE * 1.0)),
        ("--angular", "0.5", math.atan(dm.WHEEL_BASE * 0.5 / 0.3)),  # the bicycle model
    ],
)
def test_an_ackermann_car_takes_a_steering_angle_curvature_or_yaw_rate(
    served: Path, option: str, value: str, phi: float
) -> None:
    reply = json.loads(
        _ok(served, "drive", "car", "--linear", "0.3", option, value, "-d", "0.5", "--json")
    )
    applied = reply["applied"]
    assert applied["steering_angle"] == pytest.approx(phi, abs=1e-12), "bicycle angle [rad]"
    assert applied["yaw_rate"] == pytest.approx(0.3 * math.tan(phi) / dm.WHEEL_BASE, abs=1e-12)
    left, right = applied["steering_angles"].values()
    assert left > phi > right > 0, "the inner (left) wheel steers more: Ackermann geometry"
    text = _ok(served, "drive", "car", "--linear", "0.3", option, value, "-d", "0.5")
    assert f"steering={phi:.4g} rad" in text and "gazebo_ros_ackermann_drive" in text


def test_odom_names_the_plugins_frames_and_follows_the_car(served: Path) -> None:
    _ok(served, "drive", "car", "--linear", "0.3", "--steering", "0.3", "-d", "1")
    _ok(served, "step", "1500")
    odom = json.loads(_ok(served, "odom", "car", "--json"))
    pose = json.loads(_ok(served, "pose", "car", "--json"))
    assert (odom["odometry_frame"], odom["robot_base_frame"]) == ("odom_car", "base_link")
    assert odom["pose"]["position"][:2] == pytest.approx([pose["x"], pose["y"]], abs=1e-9)
    assert pose["yaw"] > 0.1, "the car turned left"
    rows = {r.split("\t")[0]: r.split("\t")[1:] for r in _ok(served, "odom", "car").splitlines()}
    assert rows["frames (odometry, base)"][:2] == ["odom_car", "base_link"], "piped: a row"


@pytest.mark.parametrize(
    ("args", "needle", "fix"),
    [
        (("drive", "kobuki", "--steering", "0.3"), "steered bases", "--angular"),
        (("drive", "car", "--lateral", "0.1"), "cannot move sideways", "--linear"),
        (("drive", "car", "--angular", "0.2", "--steering", "0.1"), "not both", "one of them"),
        (("drive", "box", "--linear", "0.2"), "no drive plugin", "no joint to command"),
        (("odom", "cart"), "no drive plugin", "twin command cart"),
    ],
)
def test_bad_drive_input_is_one_message_naming_the_fix_and_exit_2(
    served: Path, args: tuple, needle: str, fix: str
) -> None:
    before = _ok(served, "pose", "car", "--json")
    proc = _twin(served, *args)
    assert proc.returncode == 2, proc.stderr
    assert needle in proc.stderr and fix in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    assert _ok(served, "pose", "car", "--json") == before, "the world is unchanged"


def test_the_fix_named_for_a_base_without_a_drive_works(served: Path) -> None:
    """The error names `twin command cart wheel_left_joint=2 --mode velocity`; run as printed,
    it turns the passive wheel and says Gazebo would leave it passive."""
    proc = _twin(served, "drive", "cart", "--linear", "0.2")
    found = re.search(r"twin (command cart \S+=\S+ --mode velocity)", proc.stderr)
    assert found, proc.stderr
    said = _ok(served, *shlex.split(found.group(1)))
    assert "passive in Gazebo" in said, said
    _ok(served, "step", "500")
    joints = {j["name"]: j for j in json.loads(_ok(served, "joints", "cart", "--json"))}
    speed = joints["wheel_left_joint"]["velocity"]
    assert speed == pytest.approx(2.0, rel=0.05), f"wheel at {speed:.3f} rad/s (commanded 2)"
    reply = json.loads(
        _ok(served, "command", "cart", "wheel_right_joint=0.5", "--mode", "effort", "--json")
    )
    assert any("passive in Gazebo" in n for n in reply["notes"]), reply


def test_no_server_exits_2_naming_a_start_that_works(tmp_path: Path, serve_world) -> None:
    """With no world served, `twin drive`, `twin odom`, `twin topics` and `twin logs` exit 2
    naming the command that starts one; that command, run as printed, serves a world the drive
    then reaches."""
    world = "no_server_yet"
    for args in (("drive", "kobuki", "--linear", "0.2"), ("odom", "kobuki"), ("topics",)):
        proc = twin_in(tmp_path, world, *args)
        assert proc.returncode == 2, f"twin {args}: exit {proc.returncode} {proc.stderr}"
        assert proc.stderr.startswith("An instance of twin is not running."), proc.stderr
        assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
    logs = twin_in(tmp_path, world, "logs")
    assert logs.returncode == 2 and f"`twin serve --world {world}`" in logs.stderr, logs.stderr
    found = re.search(r"`twin (serve[^`]*)`", proc.stderr)
    assert found, proc.stderr
    command = shlex.split(found.group(1))
    assert command[:3] == ["serve", "--world", world], command
    with serve_world(tmp_path, world, *command[3:]):
        path = tmp_path / "kobuki.urdf"
        path.write_text(dm.two_wheel_base(KOBUKI))
        twin_ok(tmp_path, world, "spawn", str(path), "--name", "kobuki", "--on-ground")
        twin_ok(tmp_path, world, "drive", "kobuki", "--linear", "0.2", "-d", "0.5")
        twin_ok(tmp_path, world, "step", "700")
        pose = json.loads(twin_ok(tmp_path, world, "pose", "kobuki", "--json"))
    assert pose["x"] > 0.05, f"the base drove {pose['x']:.3f} m on the started world"


def test_the_fix_named_for_an_arm_without_a_drive_moves_it(served: Path) -> None:
    """A JointTrajectoryController's joints take positions only: `twin drive arm` names
    `twin command arm shoulder=0.5 --mode position`, which, run as printed, moves the joint."""
    proc = _twin(served, "drive", "arm", "--linear", "0.2")
    assert proc.returncode == 2 and "twin trajectory arm FILE" in proc.stderr, proc.stderr
    found = re.search(r"twin (command arm \S+=\S+ --mode position)", proc.stderr)
    assert found, proc.stderr
    _ok(served, *shlex.split(found.group(1)))
    _ok(served, "step", "1500")
    joints = {j["name"]: j for j in json.loads(_ok(served, "joints", "arm", "--json"))}
    angle = joints["shoulder"]["position"]
    assert angle == pytest.approx(0.5, abs=0.01), f"shoulder at {angle:.4f} rad (commanded 0.5)"


@pytest.mark.parametrize("speed", [1.5, -3.0])
def test_a_command_on_a_wheel_a_drive_turns_stops_the_drive_and_says_so(
    served: Path, speed: float
) -> None:
    """A wheel commanded by hand after a drive keeps that command (it is not overwritten at the
    drive's next update), the reply names the drive it stopped, and twin drive restarts it."""
    _ok(served, "drive", "kobuki", "--linear", "0.2")
    _ok(served, "step", "200")
    said = _ok(served, "command", "kobuki", f"wheel_left_joint={speed}", "--mode", "velocity")
    assert "drive [kobuki_controller]" in said and "stopped" in said, said
    _ok(served, "step", "1000")
    joints = {j["name"]: j for j in json.loads(_ok(served, "joints", "kobuki", "--json"))}
    held = joints["wheel_left_joint"]["velocity"]
    assert held == pytest.approx(speed, rel=0.05), f"wheel at {held:.3f} rad/s (given {speed})"
    _ok(served, "drive", "kobuki", "--linear", "0")  # the drive runs again and stops the base
    _ok(served, "step", "1000")
    joints = {j["name"]: j for j in json.loads(_ok(served, "joints", "kobuki", "--json"))}
    left = joints["wheel_left_joint"]["velocity"]
    assert abs(left) < 0.05, f"wheel at {left:.3f} rad/s after twin drive --linear 0"
    again = _ok(served, "command", "kobuki", "wheel_left_joint=0", "--mode", "velocity")
    assert "stopped" in again, again
