"""A drive updates at the rate its plugin declares, as Gazebo calls it: gazebo_ros' `update_rate`
(`updateRate`; default 100 Hz), the controller manager's `update_rate` for diff_drive_controller,
every physics step for gz-sim's DiffDrive (its `odom_publish_frequency` only throttles the
odometry it publishes) and for a rate of 0 or one faster than the step. Oracle: the number of
updates over one second of sim time, counted on the controller, and the plugin's declared rate.
"""

from __future__ import annotations

import math
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import controller_of, drive
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

PATH_TOLERANCE = 0.02  # fraction of the distance driven


def _ros_diff(rate: str) -> str:
    """gazebo_ros' diff drive on two_wheel_base with a slow wheel ramp and `rate` tags."""
    return (
        '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
        "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
        "</wheel_separation><wheel_diameter>0.1</wheel_diameter><max_wheel_acceleration>0.2"
        f"</max_wheel_acceleration>{rate}</plugin>"
    )


GZ_DIFF_SLOW_ODOM = (
    '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive"><left_joint>'
    "wheel_left_joint</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>"
    "0.3</wheel_separation><wheel_radius>0.05</wheel_radius><odom_publish_frequency>1"
    "</odom_publish_frequency></plugin>"
)
WHEELS = ("wheel_left_joint", "wheel_right_joint")


def _world(tmp_path: Path, plugin: str, controller_rate: float = 100.0) -> World:
    robot = dm.two_wheel_base(plugin)
    if plugin == dm.ROS2_CONTROL:
        left, right = WHEELS[:1], WHEELS[1:]
        robot = dm.with_diff_drive_controller(robot, left, right, tmp_path, rate=controller_rate)
    return dm.settled_base(tmp_path, robot)


@pytest.mark.parametrize(
    ("plugin", "controller_rate", "per_second"),
    [
        (_ros_diff("<update_rate>30</update_rate>"), 0.0, 30),
        (_ros_diff("<updateRate>50</updateRate>"), 0.0, 50),
        (_ros_diff(""), 0.0, 100),  # the plugin's default
        (_ros_diff("<update_rate>0</update_rate>"), 0.0, 1000),  # every step
        (_ros_diff("<update_rate>5000</update_rate>"), 0.0, 1000),  # faster than the step
        (GZ_DIFF_SLOW_ODOM, 0.0, 1000),
        (dm.ROS2_CONTROL, 40.0, 40),
    ],
    ids=["ros_30", "ros1_50", "ros_default", "ros_0", "ros_5000", "gz_diff_drive", "ros2_control"],
)
def test_a_drive_updates_at_its_plugins_rate(
    tmp_path: Path, plugin: str, controller_rate: float, per_second: int
) -> None:
    """Counted over the first and second second of a turn, on the controller and, for gazebo_ros'
    drive, whose right wheel ramps at 0.2 m/s² towards its 0.45 m/s for 2.25 s (a new target at
    every update), as the targets the world receives for that wheel, step by step."""
    world = _world(tmp_path, plugin, controller_rate)
    assert world.model.opt.timestep == pytest.approx(1e-3), "the counts assume 1 ms steps"
    drive(world, "base", 0.3, angular=1.0)
    controller = controller_of(world, "base")
    wheel = next(key for key in world.commands() if key.endswith(WHEELS[1]))
    ramped = "libgazebo_ros_diff_drive" in plugin
    for _ in range(2):
        before, changes, target = controller.updates, 0, world.commands()[wheel].target
        for _ in range(1000):
            world.step(1)
            changes += world.commands()[wheel].target != target
            target = world.commands()[wheel].target
        assert controller.updates - before == per_second
        if ramped:
            assert changes == per_second, f"{changes} new wheel targets in 1 s"


def _distance_driven(world: World, duration: float) -> float:
    """[m] from the start to where the base is 1 s after 0.3 m/s for `duration` seconds."""
    start = world.get_pose("base")
    drive(world, "base", 0.3, duration=duration)
    world.step(round((duration + 1.0) / world.model.opt.timestep))
    end = world.get_pose("base")
    return math.hypot(end.x - start.x, end.y - start.y)


def test_a_gz_diff_drive_with_slow_odometry_drives_its_path(tmp_path: Path) -> None:
    """gz-sim's DiffDrive sets its wheels' speeds at every step whatever its odometry rate: at
    0.3 m/s for 3.5 s it drives 1.05 m (2 %); updates at the odometry's 1 Hz would stop it at a
    whole second, 0.9 or 1.2 m."""
    driven = _distance_driven(_world(tmp_path, GZ_DIFF_SLOW_ODOM), duration=3.5)
    assert driven == pytest.approx(1.05, rel=PATH_TOLERANCE), f"drove {driven:.4f} m of 1.05"


@pytest.mark.parametrize(
    ("plugin", "controller_rate"),
    [
        (_ros_diff("<update_rate>10</update_rate>").replace("0.2</max", "0</max"), 0.0),
        (_ros_diff("<update_rate>20</update_rate>").replace("0.2</max", "0</max"), 0.0),
        (dm.ROS2_CONTROL, 10.0),
    ],
    ids=["ros_10", "ros_20", "ros2_control_10"],
)
def test_a_slow_drive_holds_a_timed_command_for_its_whole_duration(
    tmp_path: Path, plugin: str, controller_rate: float
) -> None:
    """0.3 m/s for 2 s at 10 or 20 updates a second drives 0.6 m. The command reaches the
    plugin at its next update, as a cmd_vel does in Gazebo, and so does the stop at the end of
    the duration: the wheels turn for 2 s. Stopped at the update the duration ends on, they
    turned one update less (0.57 m at 10 Hz, 5 % short)."""
    driven = _distance_driven(_world(tmp_path, plugin, controller_rate), duration=2.0)
    assert driven == pytest.approx(0.6, rel=PATH_TOLERANCE), f"drove {driven:.4f} m of 0.6"


def test_a_timed_command_a_day_into_a_world_still_runs_its_whole_duration(
    tmp_path: Path,
) -> None:
    """data.time sums the step, so a day in, an update on a command's end reads it up to about
    1e-8 s late: the end must still be seen at the update after it (0.6 m at 10 Hz), not one
    update early (0.57 m)."""
    robot = tmp_path / "base.urdf"
    plugin = _ros_diff("<update_rate>10</update_rate>").replace("0.2</max", "0</max")
    robot.write_text(dm.two_wheel_base(plugin))
    world = World()
    world.data.time = 86400.0  # an empty world a day in: nothing to disturb
    world.spawn(SpawnRequest(str(robot), on_ground=True), name="base")
    world.step(300)
    driven = _distance_driven(world, duration=2.0)
    assert driven == pytest.approx(0.6, rel=PATH_TOLERANCE), f"drove {driven:.4f} m of 0.6"
