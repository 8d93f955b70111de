"""ros2_control's diff_drive_controller, read from the controller manager's parameter file that
the robot's gazebo_ros2_control / gz_ros2_control plugin names, becomes the base's drive.

Robots written here: the two-wheel base of the drive tests with velocity interfaces on its
wheels. The drive's motion against the unicycle model is checked with the other drive families
(tests/twin_cli/control/test_drive_families.py); here: the parameters, the served path, and what
a broken file gives.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import drive_models as dm
import pytest

from converters.gazebo.drive_records import DiffDrive
from converters.pipeline import convert_full

WHEELS = ("wheel_left_joint", "wheel_right_joint")
INTERFACES = "".join(
    f'<joint name="{j}"><command_interface name="velocity"/><state_interface name="position"/>'
    "</joint>"
    for j in WHEELS
)
YAML = """controller_manager:
  ros__parameters:
    update_rate: 50
    base_controller:
      type: diff_drive_controller/DiffDriveController
base_controller:
  ros__parameters:
    left_wheel_names: ["wheel_left_joint"]
    right_wheel_names: ["wheel_right_joint"]
    wheel_separation: 0.25
    wheel_separation_multiplier: 1.2
    wheel_radius: 0.05
    odom_frame_id: odom_demo
    base_frame_id: base_footprint
    cmd_vel_timeout: 0.5
    linear:
      x:
        has_velocity_limits: true
        max_velocity: 0.4
        has_acceleration_limits: true
        max_acceleration: 1.5
    angular.z.max_velocity: 2.0
"""


def _base(tmp_path: Path, yaml: str | None = YAML, plugin: str = "gz_ros2_control-system") -> Path:
    """The base, with its parameter file beside it (`yaml` None: no file)."""
    tag = f'<plugin filename="{plugin}" name="control"><parameters>ddc.yaml</parameters></plugin>'
    block = (
        '<ros2_control name="sim" type="system"><hardware><plugin>gz_ros2_control/GazeboSimSystem'
        f"</plugin></hardware>{INTERFACES}</ros2_control>"
    )
    text = dm.two_wheel_base(tag).replace("</robot>", f"{block}</robot>")
    (tmp_path / "base.urdf").write_text(text)
    if yaml is not None:
        (tmp_path / "ddc.yaml").write_text(yaml)
    return tmp_path / "base.urdf"


def _twin(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    code = "import sys; from twin_cli.cli.app import main; sys.argv[0] = 'twin'; main()"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd, timeout=120
    )


def test_the_controllers_parameters_become_the_drive(tmp_path: Path) -> None:
    done = convert_full(_base(tmp_path))
    (drive,) = [p for p in done.plugins if isinstance(p, DiffDrive)]
    assert (drive.left_joints, drive.right_joints) == ((WHEELS[0],), (WHEELS[1],))
    assert drive.wheel_separation == pytest.approx(0.25 * 1.2, rel=1e-12), "× the multiplier"
    assert drive.wheel_diameter == pytest.approx(0.1, rel=1e-12)
    assert (drive.max_linear_velocity, drive.max_angular_velocity) == (0.4, 2.0)
    assert drive.update_rate == 50 and drive.max_wheel_acceleration == 0.0
    assert drive.twist_acceleration == (-1.5, 1.5, -math.inf, math.inf), "min is -max"
    assert (drive.odometry_frame, drive.robot_base_frame) == ("odom_demo", "base_footprint")
    assert drive.family == "diff_drive_controller" and drive.odometry_source == "encoder"
    details = [e.detail for e in done.report.entries]
    assert any("holds for cmd_vel_timeout 0.5 s" in d for d in details), "the timeout is said"
    assert drive.command_timeout == 0.5
    plugin = "<plugin> 'control' gz_ros2_control-system: enables the robot's"
    assert any(d.startswith(plugin) for d in details), "gz_ros2_control is run, not 'not run'"


def test_a_limit_whose_flag_is_false_does_not_limit(tmp_path: Path) -> None:
    yaml = YAML.replace("has_velocity_limits: true", "has_velocity_limits: false")
    done = convert_full(_base(tmp_path, yaml))
    (drive,) = [p for p in done.plugins if isinstance(p, DiffDrive)]
    assert math.isinf(drive.max_linear_velocity) and drive.max_angular_velocity == 2.0


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        (("wheel_radius: 0.05", "wheel_radius: wide"), "wheel_radius is 'wide', not a number"),
        (("    wheel_radius: 0.05\n", ""), "wheel_radius is None, not a length > 0"),
        (('left_wheel_names: ["wheel_left_joint"]', "left_wheel_names: 3"), "left_wheel_names"),
        (('["wheel_right_joint"]', '["no_such_joint"]'), "right_wheel_names names joint"),
    ],
)
def test_a_broken_controller_is_one_clear_error(
    tmp_path: Path, change: tuple[str, str], needle: str
) -> None:
    _base(tmp_path, YAML.replace(*change))
    result = _twin("convert", "base.urdf", "-o", "out", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert needle in result.stderr and "Traceback" not in result.stderr, result.stderr
    assert "ddc.yaml" in result.stderr and "controller 'base_controller'" in result.stderr
    assert not (tmp_path / "out").exists(), "nothing written"


def test_humbles_limits_count_only_with_their_flags_under_gazebo_classic(tmp_path: Path) -> None:
    """Gazebo Classic's plugin runs Humble's controller: `angular.z.max_velocity` without
    `has_velocity_limits: true` does not limit; gz_ros2_control's (Jazzy's) does."""
    classic = convert_full(_base(tmp_path, plugin="libgazebo_ros2_control.so"))
    (drive,) = [p for p in classic.plugins if isinstance(p, DiffDrive)]
    assert drive.max_linear_velocity == 0.4 and math.isinf(drive.max_angular_velocity)


@pytest.mark.parametrize(
    "layout",
    ["own_type", "namespaced", "wildcard", "nested", "split_files"],
)
def test_parameter_files_are_read_as_ros_reads_them(tmp_path: Path, layout: str) -> None:
    """The controller's type among its own parameters (gz_ros2_control's demos), node names
    with a namespace or `/**`, nested namespace maps, and the manager and the controller in two
    files: each gives the same drive."""
    params = (
        'left_wheel_names: ["wheel_left_joint"]\n'
        'right_wheel_names: ["wheel_right_joint"]\n'
        "wheel_separation: 0.25\nwheel_radius: 5e-2\n"
    )
    body = "".join(f"      {line}\n" for line in params.splitlines())
    manager = "controller_manager:\n  ros__parameters:\n    dd:\n      type: {t}\n"
    kind = "diff_drive_controller/DiffDriveController"
    texts = {
        "own_type": "controller_manager:\n  ros__parameters:\n    update_rate: 100\n"
        f"dd:\n  ros__parameters:\n    type: {kind}\n{body.replace('      ', '    ')}",
        "namespaced": manager.format(t=kind).replace(
            "controller_manager:", "/robot/controller_manager:"
        )
        + f"/robot/dd:\n  ros__parameters:\n{body.replace('      ', '    ')}",
        "wildcard": manager.format(t=kind).replace("controller_manager:", "/**/controller_manager:")
        + f"/**/dd:\n  ros__parameters:\n{body.replace('      ', '    ')}",
        "nested": "robot:\n  "
        + manager.format(t=kind).replace("\n", "\n  ").rstrip()
        + f"\n  dd:\n    ros__parameters:\n{body}",
    }
    plugin = '<plugin filename="gz_ros2_control-system" name="control">{}</plugin>'
    if layout == "split_files":
        (tmp_path / "a.yaml").write_text(manager.format(t=kind))
        (tmp_path / "b.yaml").write_text(
            f"dd:\n  ros__parameters:\n{body.replace('      ', '    ')}"
        )
        files = "<parameters>a.yaml</parameters><parameters>b.yaml</parameters>"
    else:
        (tmp_path / "ddc.yaml").write_text(texts[layout])
        files = "<parameters>ddc.yaml</parameters>"
    block = (
        '<ros2_control name="sim" type="system"><hardware><plugin>gz_ros2_control/GazeboSimSystem'
        f"</plugin></hardware>{INTERFACES}</ros2_control>"
    )
    text = dm.two_wheel_base(plugin.format(files)).replace("</robot>", f"{block}</robot>")
    (tmp_path / "base.urdf").write_text(text)
    done = convert_full(tmp_path / "base.urdf")
    (drive,) = [p for p in done.plugins if isinstance(p, DiffDrive)]
    assert (drive.name, drive.wheel_separation, drive.wheel_diameter) == ("dd", 0.25, 0.1)


def test_a_text_description_reads_its_parameters_beside_where_it_was_sent_from(
    tmp_path: Path,
) -> None:
    from converters.pipeline import convert_text

    robot = _base(tmp_path)
    done = convert_text(robot.read_text(), source="<xml>", base_dir=tmp_path)
    assert [p.name for p in done.plugins if isinstance(p, DiffDrive)] == ["base_controller"]


def test_a_ros_cmd_vel_holds_for_the_controllers_timeout(tmp_path: Path) -> None:
    """The bridge's cmd_vel inputs carry cmd_vel_timeout (0.5 s in the file) as the command's
    duration, as the controller stops a base whose commands stop."""
    from twin_cli.ros.commands import entity_inputs
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    world = World()
    world.spawn(SpawnRequest(str(_base(tmp_path)), on_ground=True), name="base")
    drives = [i for i in entity_inputs(world)["base"] if i.mode is None]
    assert [(i.topic, i.type) for i in drives] == [
        ("/base/base_controller/cmd_vel", "geometry_msgs/msg/TwistStamped")
    ], "one topic of one type: the controller's default, use_stamped_vel true"
    assert {i.timeout for i in drives} == {0.5}
    from twin_cli.live.catalogue import live_topics

    assert "/base/base_controller/odom" in {t.name for t in live_topics(world)}, "its ~/odom"


def test_an_unreadable_parameter_file_is_a_warning_and_no_drive(tmp_path: Path) -> None:
    done = convert_full(_base(tmp_path, yaml=None))
    assert not [p for p in done.plugins if isinstance(p, DiffDrive)]
    warnings = [e.detail for e in done.report.entries if e.outcome.value == "warning"]
    assert any("ddc.yaml not read" in w for w in warnings), warnings


def test_a_served_base_drives_from_its_controller_yaml(tmp_path: Path, serve_world) -> None:
    """Spawned into a served world (converted in the bounded child, built from its read log),
    the base drives straight at the commanded speed and its odometry has the YAML's frames."""
    robot = _base(tmp_path, plugin="libgazebo_ros2_control.so")
    with serve_world(tmp_path / "run", "ddc", "--paused") as (client, _):
        client.spawn(str(robot), name="base", pose={"z": 0.06})
        client.step(300)
        start = client.pose("base")
        reply = client.request("POST", "/entities/base/drive", body={"linear": 0.3, "duration": 2})
        assert "diff_drive_controller" in str(reply), reply
        client.step(2500)
        end = client.pose("base")
        odom = client.request("GET", "/entities/base/odom")
    # linear.x.max_velocity 0.4 does not clip 0.3; the rims ramp at 1.5 m/s² for 0.2 s each way.
    expected = 0.3 * 2.0
    moved = math.hypot(end["x"] - start["x"], end["y"] - start["y"])
    assert moved == pytest.approx(expected, rel=0.02), f"{moved:.4f} m of {expected} m"
    assert (odom["odometry_frame"], odom["robot_base_frame"]) == ("odom_demo", "base_footprint")


@pytest.mark.parametrize("bound", [0.5, 1.0, 2.0])
def test_wheel_interface_min_max_does_not_clip_the_controllers_speeds(
    tmp_path: Path, bound: float
) -> None:
    """Wheels declared ±`bound` rad/s (below the 6 rad/s that 0.3 m/s asks of R = 0.05 m):
    gazebo_ros2_control applies no min/max to velocity commands, so the base drives 1.5 m in
    5 s as without them, and the drive's reply names the speeds the wheels really turn at."""
    from twin_cli.control import drive

    bounded = INTERFACES.replace(
        '<command_interface name="velocity"/>',
        f'<command_interface name="velocity"><param name="min">{-bound}</param>'
        f'<param name="max">{bound}</param></command_interface>',
    )
    path = _base(tmp_path, YAML.replace("max_velocity: 0.4", "max_velocity: 1.0"))
    robot = dm.settled_base(tmp_path, path.read_text().replace(INTERFACES, bounded))
    start = robot.get_pose("base").x
    reply = drive(robot, "base", 0.3, 0.0, 5.0)
    robot.step(2500)
    speeds = {s.name: s.velocity for s in robot.joint_states("base") if s.name in WHEELS}
    robot.step(2600)
    moved = robot.get_pose("base").x - start
    assert moved == pytest.approx(1.5, rel=0.02), f"drove {moved:.4f} m of 1.5"
    for side, wheel in zip(("left", "right"), WHEELS, strict=True):
        asked = reply["applied"]["wheel_speeds"][side]
        assert asked == pytest.approx(6.0, rel=1e-9), reply
        assert speeds[wheel] == pytest.approx(asked, rel=0.02), f"{wheel} at {speeds[wheel]:.3f}"


@pytest.mark.parametrize("name", ["base.xacro.urdf", "base.urdf"])
def test_a_file_whose_only_xacro_is_a_find_is_expanded_and_drives(
    tmp_path: Path, name: str
) -> None:
    """A description written as gz_ros2_control's demos write theirs: no `<xacro:` tag, its
    parameter file named by `$(find pkg)/config/...` and the xacro namespace declared (under a
    `.xacro.urdf` name, and under a plain `.urdf` one). ROS launch files run xacro on it, so the
    file is found in the package and the base drives 1.5 m in 5 s at 0.3 m/s (the rims ramp at
    1.5 m/s² for 0.2 s each way, which cancel; 2 % as the drive families' path bound)."""
    from twin_cli.control import drive
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    package = tmp_path / "demo_pkg"
    (package / "config").mkdir(parents=True)
    (package / "config" / "ddc.yaml").write_text(
        YAML.replace("max_velocity: 0.4", "max_velocity: 1")
    )
    text = _base(tmp_path, yaml=None).read_text()
    text = text.replace("<parameters>ddc.yaml", "<parameters>$(find demo_pkg)/config/ddc.yaml")
    text = text.replace("<robot ", '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" ', 1)
    (tmp_path / "elsewhere").mkdir()
    path = tmp_path / "elsewhere" / name
    path.write_text(text)
    done = convert_full(path, package_paths={"demo_pkg": package})
    assert [p.family for p in done.plugins if isinstance(p, DiffDrive)] == ["diff_drive_controller"]
    world = World()
    request = SpawnRequest(str(path), package_paths={"demo_pkg": str(package)}, on_ground=True)
    world.spawn(request, name="base")
    world.step(300)
    start = world.get_pose("base").x
    drive(world, "base", 0.3, 0.0, 5.0)
    world.step(5600)
    moved = world.get_pose("base").x - start
    assert moved == pytest.approx(1.5, rel=0.02), f"drove {moved:.4f} m of 1.5"


ANGULAR_LIMITS = (
    "    angular.z.has_acceleration_limits: true\n    angular.z.max_acceleration: 0.5\n"
)


JAZZY, HUMBLE = "gz_ros2_control-system", "libgazebo_ros2_control.so"


@pytest.mark.parametrize(
    ("plugin", "extra", "linear", "angular", "at_end", "after_stop"),
    [
        # ω rises at 0.5 rad/s² for 2 s: 3 rad at the end of 4 s at 1 rad/s, and falls at -max
        (JAZZY, ANGULAR_LIMITS, 0.0, 1.0, 3.0, 4.0),
        # v rises at 1.5 m/s² and brakes at the given 0.5 m/s²: 1.17 m, then 0.09 m more
        (JAZZY, "    linear.x.max_deceleration: -0.5\n", 0.3, 0.0, 1.17, 1.17 + 0.09),
        (HUMBLE, "    linear.x.min_acceleration: -0.5\n", 0.3, 0.0, 1.17, 1.17 + 0.09),
        # Jazzy passes min_acceleration to no limiter: it brakes at -max, 0.03 m more
        (JAZZY, "    linear.x.min_acceleration: -0.5\n", 0.3, 0.0, 1.17, 1.17 + 0.03),
        # backward, v speeds up at the given 0.25 m/s² (1.2 s) and brakes at +max
        (JAZZY, "    linear.x.max_acceleration_reverse: -0.25\n", -0.3, 0.0, -1.02, -1.05),
        # reversing is clamped at the given linear.x.min_velocity, not at -max_velocity
        (JAZZY, "    linear.x.min_velocity: -0.1\n", -0.3, 0.0, -0.1 * (4.0 - 0.1 / 3.0), -0.4),
    ],
    ids=["angular", "jazzy_brake", "humble_brake", "jazzy_min_accel", "jazzy_reverse", "min_vel"],
)
def test_the_controllers_speed_limiters_bound_v_and_w_each(
    tmp_path: Path,
    plugin: str,
    extra: str,
    linear: float,
    angular: float,
    at_end: float,
    after_stop: float,
) -> None:
    """diff_drive_controller's speed limiters bound the change of linear.x and of angular.z and
    the speeds between min_velocity (unset: -max_velocity) and max_velocity. The change is
    bounded by max_acceleration and a braking bound: Humble's min_acceleration (signed; unset:
    -max); Jazzy's rate limiter picks its pair by the last command's sign: forward
    (max_deceleration, else max_acceleration_reverse, else -max; max_acceleration), backward
    (max_acceleration_reverse, else -max; max_deceleration_reverse, else +max).
    Oracle: those ramps in closed form, the heading [rad] (in place) or the distance [m] at the
    end of a 4 s command and 2.5 s later; bound: 2 % as the drive families' path bound."""
    from twin_cli.control import drive

    yaml = YAML.replace("max_velocity: 0.4", "max_velocity: 1.0").replace(
        "    angular.z.max_velocity: 2.0\n", f"    angular.z.max_velocity: 2.0\n{extra}"
    )
    robot = dm.settled_base(tmp_path, _base(tmp_path, yaml, plugin).read_text())
    start = robot.get_pose("base")

    def progress() -> float:
        end = robot.get_pose("base")
        return end.x - start.x if angular == 0 else math.remainder(end.yaw - start.yaw, 2 * math.pi)

    drive(robot, "base", linear, angular, 4.0)
    robot.step(4000)
    first = progress()
    robot.step(2500)
    total = progress() if angular == 0 else first + math.remainder(progress() - first, 2 * math.pi)
    assert first == pytest.approx(at_end, rel=0.02), f"{first:.4f} at the end of the command"
    assert total == pytest.approx(after_stop, rel=0.02), f"{total:.4f} after the stop"
