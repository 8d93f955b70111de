"""A skid steer in a world, driven open loop as Gazebo's plugins drive it: its wheels get the
unicycle's rim speeds v ∓ ω·b/2 for the plugin's separation b, and nothing reads the base's
heading. Robots the tests write (tests/drive_models.py): four wheels of radius R, half the track
c = 0.15 m, half the wheel base a = 0.06 m (a/c = 0.4), equal loads, μ = 1 on every contact.

Oracles: Coulomb friction's turn rate ω/(1 + (a/c)²) for wheels run at the unicycle's speeds; the
commanded speed on a straight line; the plugin's odometry formula, integrated here from the
wheel joints at the plugin's update times. twin's turn is measured as the mean rate over half a
turn of heading, after the wheels' spin-up.
"""

from __future__ import annotations

import math
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import controller_of, drive, odometry
from twin_cli.world import World
from twin_cli.world.engine import Pose

A, C = dm.SKID_A, dm.TRACK / 2  # half the wheel base and half the track of skid_steer_bot [m]
COULOMB_FACTOR, COULOMB_SHORT, COULOMB_OVER = dm.COULOMB_FACTOR, dm.COULOMB_SHORT, dm.COULOMB_OVER
SPEED_TOLERANCE = 0.02  # fraction of the commanded speed on a straight line
STRAIGHT_HEADING = 0.01  # [rad] heading change allowed over a straight run
ODOM_FORMULA = 1e-9  # [m] odometry against the plugin's formula on the same wheel joints
LEFT = ("left_front_joint", "left_rear_joint")
RIGHT = ("right_front_joint", "right_rear_joint")
SKID_ROS2 = (  # ROS 2's diff drive with two wheel pairs, a wheel ramp, encoder odometry
    '<plugin name="dd4" filename="libgazebo_ros_diff_drive.so"><num_wheel_pairs>2'
    "</num_wheel_pairs><left_joint>left_front_joint</left_joint><right_joint>right_front_joint"
    "</right_joint><left_joint>left_rear_joint</left_joint><right_joint>right_rear_joint"
    "</right_joint><wheel_separation>0.3</wheel_separation><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><wheel_diameter>0.1</wheel_diameter>"
    "<max_wheel_torque>5</max_wheel_torque><max_wheel_acceleration>1.0"
    "</max_wheel_acceleration><odometry_source>0</odometry_source></plugin>"
)
GZ_PAIRS = (  # gz-sim's DiffDrive with two joints a side
    '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive"><left_joint>'
    "left_front_joint</left_joint><left_joint>left_rear_joint</left_joint><right_joint>"
    "right_front_joint</right_joint><right_joint>right_rear_joint</right_joint>"
    "<wheel_separation>0.3</wheel_separation><wheel_radius>0.05</wheel_radius></plugin>"
)


def _world(tmp_path: Path, plugin: str, multiplier: float = 1.0, wheelbase: float = 2 * A) -> World:
    """A skid_steer_bot `wheelbase` long with `plugin` (ROS2_CONTROL: a diff_drive_controller
    with `multiplier`), spawned on the ground as `base` and settled."""
    robot = dm.skid_steer_bot(plugin, wheelbase=wheelbase)
    if plugin == dm.ROS2_CONTROL:
        robot = dm.with_diff_drive_controller(robot, LEFT, RIGHT, tmp_path, multiplier)
    return dm.settled_base(tmp_path, robot, "skid.urdf")


def _mean_turn_rate(world: World, linear: float, angular: float) -> float:
    """The base's mean yaw rate [rad/s] over half a turn of heading, after 0.5 s of spin-up."""
    drive(world, "base", linear, angular=angular)
    world.step(500)
    last, start, turned = world.get_pose("base").yaw, float(world.data.time), 0.0
    while abs(turned) < math.pi and world.data.time - start < 30.0:
        world.step(10)
        yaw = world.get_pose("base").yaw
        turned, last = turned + math.remainder(yaw - last, 2 * math.pi), yaw
    return turned / (float(world.data.time) - start)


@pytest.mark.parametrize(
    ("plugin", "linear", "angular"),
    [
        (dm.SKID_STEER_ROS1, 0.3, 0.5),
        (dm.SKID_STEER_ROS1, 0.0, 1.0),
        (SKID_ROS2, 0.1, 0.3),
        (GZ_PAIRS, 0.3, -0.5),
    ],
    ids=["ros1_skid_steer", "ros1_in_place", "ros2_two_pairs", "gz_diff_drive_pairs"],
)
def test_a_skid_steer_turns_as_coulomb_friction_lets_it(
    tmp_path: Path, plugin: str, linear: float, angular: float
) -> None:
    """Below the command, by Coulomb's 1/(1 + (a/c)²)."""
    rate = _mean_turn_rate(_world(tmp_path, plugin), linear, angular)
    ratio = rate / (angular * COULOMB_FACTOR)
    assert 1.0 - COULOMB_SHORT <= ratio <= 1.0 + COULOMB_OVER, (
        f"turns at {rate:.4f} rad/s for {angular} rad/s: {ratio:.3f} of Coulomb's "
        f"{angular * COULOMB_FACTOR:.4f}"
    )


# Longer wheel bases turn further below Coulomb's rate than COULOMB_SHORT (measured, ROS 1's
# skid steer at 0.3 m/s and 0.5 rad/s, mean over half a turn of heading), where a rigid-contact
# calculation of this base (the four wheels' friction balanced in force and moment) gives
# Coulomb's rate exactly.
LONG_BASES = {
    0.2: "a/c 0.67: 0.837 of Coulomb's rate",
    0.3: "a/c 1.0: 0.728 of Coulomb's rate",
}


@pytest.mark.parametrize(
    "wheelbase",
    [
        pytest.param(w, marks=pytest.mark.xfail(reason=LONG_BASES[w], strict=True))
        if w in LONG_BASES
        else w
        for w in (2 * A, 0.2, 0.3)
    ],
)
def test_a_skid_steer_of_any_wheel_base_turns_as_coulomb_friction_lets_it(
    tmp_path: Path, wheelbase: float
) -> None:
    """Coulomb's 1/(1 + (a/c)²) for a = wheelbase/2: the law's dependence on the layout."""
    linear, angular = 0.3, 0.5
    world = _world(tmp_path, dm.SKID_STEER_ROS1, wheelbase=wheelbase)
    rate = _mean_turn_rate(world, linear, angular)
    coulomb = angular / (1.0 + (wheelbase / 2 / C) ** 2)
    ratio = rate / coulomb
    assert 1.0 - COULOMB_SHORT <= ratio <= 1.0 + COULOMB_OVER, (
        f"a/c {wheelbase / 2 / C:.2f}: turns at {rate:.4f} rad/s, {ratio:.3f} of Coulomb's "
        f"{coulomb:.4f}"
    )


@pytest.mark.parametrize("multiplier", [1.0, 1.0 + (A / C) ** 2])
def test_a_wheel_separation_multiplier_of_coulombs_turns_it_as_commanded(
    tmp_path: Path, multiplier: float
) -> None:
    """diff_drive_controller drives the wheels with the separation times its
    wheel_separation_multiplier: 1 + (a/c)² makes Coulomb's rate the command, and twin's turn
    within COULOMB_SHORT of it (measured 1 % short); without it the base turns at Coulomb's rate
    below the command, 1/(1 + (a/c)²) = 0.862 of it (measured 0.853)."""
    world = _world(tmp_path, dm.ROS2_CONTROL, multiplier)
    assert controller_of(world, "base").plugin.wheel_separation == pytest.approx(C * 2 * multiplier)
    ratio = _mean_turn_rate(world, 0.2, 0.5) / 0.5
    as_commanded = 1.0 - COULOMB_SHORT <= ratio <= 1.0 + COULOMB_OVER
    assert as_commanded == (multiplier > 1.0), f"multiplier {multiplier:.2f}: {ratio:.3f} of ω"


@pytest.mark.parametrize("plugin", [dm.SKID_STEER_ROS1, SKID_ROS2, GZ_PAIRS])
@pytest.mark.parametrize("speed", [0.2, 0.5])
def test_a_skid_steer_drives_straight_at_its_command(
    tmp_path: Path, plugin: str, speed: float
) -> None:
    world = _world(tmp_path, plugin)
    drive(world, "base", speed)
    world.step(1000)  # past the ramp
    p0, t0 = world.get_pose("base"), float(world.data.time)
    world.step(2000)
    p1 = world.get_pose("base")
    measured = math.hypot(p1.x - p0.x, p1.y - p0.y) / (float(world.data.time) - t0)
    assert measured == pytest.approx(speed, rel=SPEED_TOLERANCE), f"{measured:.4f} m/s"
    assert abs(math.remainder(p1.yaw - p0.yaw, 2 * math.pi)) < STRAIGHT_HEADING


def _side_means(world: World, field: str) -> tuple[float, float]:
    """The mean joint position [rad] (`qpos`) or speed [rad/s] (`qvel`) of each side."""
    m, d = world.model, world.data
    values = getattr(d, field)
    addr = "jnt_qposadr" if field == "qpos" else "jnt_dofadr"

    def mean(joints: tuple[str, ...]) -> float:
        return sum(float(values[getattr(m, addr)[m.joint(f"base/{j}").id]]) for j in joints) / 2

    return mean(LEFT), mean(RIGHT)


def _advance(pose: tuple, distance: float, turn: float) -> tuple:
    """Siegwart's odometry step: `distance` [m] along the heading halfway through `turn` [rad]."""
    x, y, theta = pose
    mid = theta + turn / 2
    return x + distance * math.cos(mid), y + distance * math.sin(mid), theta + turn


@pytest.mark.parametrize(
    ("plugin", "multiplier"),
    [(SKID_ROS2, 1.0), (GZ_PAIRS, 1.0), (dm.ROS2_CONTROL, 1.0 + (A / C) ** 2)],
    ids=["ros2_wheel_speeds", "gz_wheel_positions", "diff_drive_controller_positions"],
)
def test_skid_steer_odometry_is_its_plugins_formula_on_the_wheel_joints(
    tmp_path: Path, plugin: str, multiplier: float
) -> None:
    """The plugin's encoder odometry, from the wheels it drives and its own separation b (times
    the multiplier): gazebo_ros samples the wheels' speeds at each update (distance r·v̄·dt,
    turn r·(v_r − v_l)·dt/b), gz-sim and diff_drive_controller take the wheels' travel since the
    last update; integrated here at the controller's update times (its rate: 100 Hz, every step,
    the controller manager's 100 Hz)."""
    world = _world(tmp_path, plugin, multiplier)
    drive(world, "base", 0.3, angular=0.5, duration=3.0)
    controller = controller_of(world, "base")
    b, r = C * 2 * multiplier, dm.R
    every = round(1.0 / (controller.rate * float(world.model.opt.timestep)))
    start = odometry(world, "base")["pose"]
    pose = (*start["position"][:2], start["rpy"][2])
    angles = _side_means(world, "qpos")
    for _ in range(3500 // every):
        world.step(every)
        if plugin == SKID_ROS2:
            left, right = _side_means(world, "qvel")
            dt = every * float(world.model.opt.timestep)
            pose = _advance(pose, r * (left + right) / 2 * dt, r * (right - left) / b * dt)
        else:
            now = _side_means(world, "qpos")
            left, right = now[0] - angles[0], now[1] - angles[1]
            pose, angles = _advance(pose, r * (left + right) / 2, r * (right - left) / b), now
    odom = odometry(world, "base")["pose"]
    got = (*odom["position"][:2], odom["rpy"][2])
    assert max(abs(g - p) for g, p in zip(got, pose, strict=True)) < ODOM_FORMULA, (got, pose)


def test_a_stopped_skid_steer_is_left_where_it_is_put(tmp_path: Path) -> None:
    """Nothing steers its heading: set to a new heading after a turn, it stays there."""
    world = _world(tmp_path, SKID_ROS2)
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(2000)  # the turn and its ramp down
    pose = world.get_pose("base")
    moved = Pose(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw + 0.05)
    world.set_pose("base", moved)
    world.step(2000)
    turned = abs(math.remainder(world.get_pose("base").yaw - moved.yaw, 2 * math.pi))
    assert turned < 1e-3, f"turned {turned:.4f} rad after a set pose on a stopped base"


def test_a_parked_skid_steer_holds_on_a_slope_after_a_turn(tmp_path: Path) -> None:
    """Oracle: a base held by its wheels on a 10° slope below its friction angle (μ 1) stays
    where it is."""
    world = _world(tmp_path, SKID_ROS2)
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(2000)
    slope = math.radians(10.0)
    world.set_gravity((-9.81 * math.sin(slope), 0.0, -9.81 * math.cos(slope)))
    world.step(2000)
    before = world.get_pose("base")
    world.step(10000)
    after = world.get_pose("base")
    slid = math.hypot(after.x - before.x, after.y - before.y)
    assert slid < 1e-3, f"slid {slid * 1e3:.3f} mm down a 10° slope in 10 s"
