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
    assert drive.max_wheel_acceleration == 1.5 and drive.update_rate == 50
    assert (drive.odometry_frame, drive.robot_base_frame) == ("odom_demo", "base_footprint")
    assert drive.family == "diff_drive_controller" and drive.odometry_source == "encoder"
    details = [e.detail for e in done.report.entries]
    assert any("cmd_vel_timeout: a command holds" in d for d in details), "what is not run is said"
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
        (('["wheel_right_joint"]', '["no_such_joint"]'), "no_such_joint"),
    ],
)
def test_a_broken_controller_is_one_clear_error(
    tmp_path: Path, change: tuple[str, str], needle: str
) -> None:
    _base(tmp_path, YAML.replace(*change))
    result = _twin("convert", "base.urdf", "-o", "out", cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert needle in result.stderr and "Traceback" not in result.stderr, result.stderr
    assert "ddc.yaml" in result.stderr or "no_such_joint" in needle, "the file is named"
    assert not (tmp_path / "out").exists(), "nothing written"


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
