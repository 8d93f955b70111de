"""Every drive family drives a straight line and a turn along its kinematic model.

Robots the test writes (tests/drive_models.py), one per plugin, on the flat ground. Oracle: the
family's kinematic model, integrated here with a 0.1 ms Euler step independently of twin's code,
from the pose the robot had when commanded: the unicycle (x' = v cos θ, y' = v sin θ, θ' = ω)
for diff drives and skid steer, the bicycle (θ' = v tan φ / L, at the fixed axle's midpoint) for
Ackermann and tricycle bases, the holonomic base (body twist vx, vy, ω) for planar move, each
through the speed ramp its plugin (or twin, for planar move) applies. Bounds: the end position
within 2 % of the distance driven and the heading within 2 % of the turn (0.02 rad on a
straight line); the plugin's odometry within 1 cm of the world pose. A skid steer is driven open
loop, as its plugin drives it, so it turns as its wheels' friction lets it: its turn is checked
against Coulomb's ω/(1 + (a/c)²) instead (test_skid_steer), and its encoder odometry, which
assumes the unicycle, only on the straight line.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import drive, odometry
from twin_cli.control.holonomic_drive import ANGULAR_RAMP, LINEAR_RAMP
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

PATH_TOLERANCE = 0.02  # fraction of the distance driven (position) and of the turn (heading)
STRAIGHT_HEADING = 0.02  # [rad] heading error allowed on a straight line
# [m] odometry against the world pose: the two-wheeled bases' encoder odometry reads 10.1-11.4 mm
# off at the end of the 1.27 m turn (their wheels slip as the turn starts and stops)
ODOM_TOLERANCE = 0.012
# [m] gz-sim AckermannSteering's encoder odometry on the 1.2 m turn: its driven rear wheels,
# whose lag the velocity servos' integral pays back while the drive ramps down (Gazebo's velocity
# constraint keeps none), read 10.0 mm (implicit) and 11.0 mm (implicitfast) off the world pose;
# gz-sim's own formula (first wheel of each side, mean steering angle) read 14 mm off on the same
# drive, so the bound is that plugin's own accuracy here, not 1 cm.
ACKERMANN_ODOM_TOLERANCE = 0.015
SETTLE = 0.5  # [s] stepped after the command's duration (the ramp down)

DIFF_ROS2 = (
    '<plugin name="dd" filename="libgazebo_ros_diff_drive.so"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><odometry_source>0</odometry_source>"
    "<odometry_frame>odom</odometry_frame><robot_base_frame>base_link</robot_base_frame></plugin>"
)
DIFF_ROS2_PAIRS = (  # ROS 2's diff drive on four wheels: a skid steer with encoder odometry
    '<plugin name="dd4" filename="libgazebo_ros_diff_drive.so"><num_wheel_pairs>2'
    "</num_wheel_pairs><left_joint>left_front_joint</left_joint><right_joint>right_front_joint"
    "</right_joint><left_joint>left_rear_joint</left_joint><right_joint>right_rear_joint"
    "</right_joint><wheel_separation>0.3</wheel_separation><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><wheel_diameter>0.1</wheel_diameter>"
    "<max_wheel_torque>5</max_wheel_torque><odometry_source>0</odometry_source></plugin>"
)
GZ_DIFF_PAIRS = (  # gz-sim's DiffDrive with two joints a side (X1- and Husky-like SDF models)
    '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive"><left_joint>'
    "left_front_joint</left_joint><left_joint>left_rear_joint</left_joint><right_joint>"
    "right_front_joint</right_joint><right_joint>right_rear_joint</right_joint>"
    "<wheel_separation>0.3</wheel_separation><wheel_radius>0.05</wheel_radius></plugin>"
)
KOBUKI = (  # a vendor's diff drive under its own name and tags (kobuki's)
    '<plugin name="kobuki_controller" filename="libgazebo_ros_kobuki.so"><publish_tf>1'
    "</publish_tf><wheel_left_joint_name>wheel_left_joint</wheel_left_joint_name>"
    "<wheel_right_joint_name>wheel_right_joint</wheel_right_joint_name><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><torque>1.0</torque>"
    "<velocity_command_timeout>0.6</velocity_command_timeout><imu_name>imu</imu_name></plugin>"
)
GZ_DIFF = (
    '<plugin filename="{file}" name="gz::sim::systems::DiffDrive"><left_joint>wheel_left_joint'
    "</left_joint><right_joint>wheel_right_joint</right_joint><wheel_separation>0.3"
    "</wheel_separation><wheel_radius>0.05</wheel_radius></plugin>"
)
ROS_ACKERMANN = (
    '<plugin name="ack" filename="libgazebo_ros_ackermann_drive.so"><front_left_joint>'
    "front_left_joint</front_left_joint><front_right_joint>front_right_joint</front_right_joint>"
    "<rear_left_joint>rear_left_joint</rear_left_joint><rear_right_joint>rear_right_joint"
    "</rear_right_joint><left_steering_joint>left_steering_joint</left_steering_joint>"
    "<right_steering_joint>right_steering_joint</right_steering_joint><max_steer>0.6</max_steer>"
    "<robot_base_frame>base_link</robot_base_frame></plugin>"
)
GZ_ACKERMANN = (
    '<plugin filename="gz-sim-ackermann-steering-system" '
    'name="gz::sim::systems::AckermannSteering"><left_joint>rear_left_joint</left_joint>'
    "<right_joint>rear_right_joint</right_joint><left_steering_joint>left_steering_joint"
    "</left_steering_joint><right_steering_joint>right_steering_joint</right_steering_joint>"
    "<kingpin_width>0.3</kingpin_width><steering_limit>0.6</steering_limit><wheel_base>0.4"
    "</wheel_base><wheel_separation>0.3</wheel_separation><wheel_radius>0.05</wheel_radius>"
    "<steer_p_gain>10</steer_p_gain></plugin>"  # steers within 0.5 s (the default 1/s: 5 s)
)
TRICYCLE = (
    '<plugin name="tri" filename="libgazebo_ros_tricycle_drive.so"><steering_joint>'
    "front_steering_joint</steering_joint><actuated_wheel_joint>front_wheel_joint"
    "</actuated_wheel_joint><encoder_wheel_left_joint>left_wheel_joint</encoder_wheel_left_joint>"
    "<encoder_wheel_right_joint>right_wheel_joint</encoder_wheel_right_joint><wheel_separation>0.3"
    "</wheel_separation><encoder_wheel_diameter>0.1</encoder_wheel_diameter>"
    "<actuated_wheel_diameter>0.1</actuated_wheel_diameter><max_wheel_torque>5</max_wheel_torque>"
    "<odometry_source>0</odometry_source></plugin>"
)
MECANUM = (
    '<plugin filename="gz-sim-mecanum-drive-system" name="gz::sim::systems::MecanumDrive">'
    "<front_left_joint>left_front_joint</front_left_joint><front_right_joint>right_front_joint"
    "</front_right_joint><back_left_joint>left_rear_joint</back_left_joint><back_right_joint>"
    "right_rear_joint</back_right_joint><wheel_separation>0.3</wheel_separation><wheelbase>0.12"
    "</wheelbase><wheel_radius>0.05</wheel_radius></plugin>"
)
# A ROS 2 base with no drive plugin: ros2_control velocity interfaces on its wheels and a
# diff_drive_controller in the controller manager's parameter file, named relative to the robot.
ROS2_CONTROL = (
    '<plugin filename="libgazebo_ros2_control.so" name="gazebo_ros2_control">'
    "<parameters>controllers.yaml</parameters></plugin>"
)
WHEEL_INTERFACES = "".join(
    f'<joint name="{j}"><command_interface name="velocity"/><state_interface name="position"/>'
    '<state_interface name="velocity"/></joint>'
    for j in ("wheel_left_joint", "wheel_right_joint")
)
CONTROLLERS_YAML = """controller_manager:
  ros__parameters:
    update_rate: 100
    diff_cont:
      type: diff_drive_controller/DiffDriveController
    joint_broad:
      type: joint_state_broadcaster/JointStateBroadcaster
diff_cont:
  ros__parameters:
    publish_rate: 50.0
    base_frame_id: base_link
    left_wheel_names: ["wheel_left_joint"]
    right_wheel_names: ["wheel_right_joint"]
    wheel_separation: 0.3
    wheel_radius: 0.05
    use_stamped_vel: false
"""


def _ros2_control_base() -> str:
    block = (
        '<ros2_control name="GazeboSystem" type="system"><hardware><plugin>'
        f"gazebo_ros2_control/GazeboSystem</plugin></hardware>{WHEEL_INTERFACES}</ros2_control>"
    )
    return dm.two_wheel_base(ROS2_CONTROL).replace("</robot>", f"{block}</robot>")


PLANAR = (
    '<plugin name="mover" filename="libgazebo_ros_planar_move.so"><update_rate>100</update_rate>'
    "<odometry_frame>odom</odometry_frame><robot_base_frame>base_link</robot_base_frame></plugin>"
)


@dataclass(frozen=True)
class Family:
    """A robot with one drive plugin, its model and the command of its turn."""

    robot: Callable[[], str]
    suffix: str
    model: str  # "unicycle", "bicycle" or "holonomic"
    turn: dict  # drive() keywords of the turn
    files: tuple[tuple[str, str], ...] = ()  # (name, text) written beside the robot
    skid: bool = False  # two wheels a side (skid_steer_bot, a/c = 0.4): it turns by friction
    odom_tolerance: float = ODOM_TOLERANCE  # [m] its odometry against the world pose


FAMILIES = {
    "gazebo_ros_diff_drive": Family(
        lambda: dm.two_wheel_base(DIFF_ROS2), "urdf", "unicycle", {"angular": 0.5}
    ),
    "gazebo_ros_skid_steer_drive": Family(
        lambda: dm.skid_steer_bot(dm.SKID_STEER_ROS1, wheelbase=0.12),
        "urdf",
        "unicycle",
        {"angular": 0.5},
        skid=True,
    ),
    "gazebo_ros_diff_drive_two_pairs": Family(
        lambda: dm.skid_steer_bot(DIFF_ROS2_PAIRS), "urdf", "unicycle", {"angular": 0.5}, skid=True
    ),
    "gz_diff_drive_two_pairs": Family(
        lambda: dm.skid_steer_bot(GZ_DIFF_PAIRS), "urdf", "unicycle", {"angular": 0.5}, skid=True
    ),
    "gazebo_ros_diff_drive_wide_wheels": Family(
        lambda: dm.two_wheel_base(DIFF_ROS2, width=0.03), "urdf", "unicycle", {"angular": 0.5}
    ),
    "vendor_kobuki": Family(
        lambda: dm.two_wheel_base(KOBUKI), "urdf", "unicycle", {"angular": 0.5}
    ),
    "ros2_control_diff_drive_controller": Family(
        _ros2_control_base,
        "urdf",
        "unicycle",
        {"angular": 0.5},
        (("controllers.yaml", CONTROLLERS_YAML),),
    ),
    "gz_diff_drive_sdf": Family(
        lambda: dm.sdf_diff_drive(GZ_DIFF.format(file="gz-sim-diff-drive-system")),
        "sdf",
        "unicycle",
        {"angular": 0.5},
    ),
    "gz_diff_drive_urdf_ignition_name": Family(
        lambda: dm.two_wheel_base(GZ_DIFF.format(file="libignition-gazebo-diff-drive-system.so")),
        "urdf",
        "unicycle",
        {"angular": 0.5},
    ),
    "gazebo_ros_ackermann_drive": Family(
        lambda: dm.ackermann_car(ROS_ACKERMANN), "urdf", "bicycle", {"steering": 0.4}
    ),
    "gz_ackermann_steering_sdf": Family(
        lambda: dm.sdf_ackermann(GZ_ACKERMANN),
        "sdf",
        "bicycle",
        {"curvature": 1.0},
        odom_tolerance=ACKERMANN_ODOM_TOLERANCE,
    ),
    "gazebo_ros_tricycle_drive": Family(
        lambda: dm.tricycle(TRICYCLE), "urdf", "bicycle", {"steering": 0.4}
    ),
    "gz_mecanum_drive": Family(
        lambda: dm.skid_steer_bot(MECANUM), "urdf", "holonomic", {"angular": 0.5, "lateral": 0.1}
    ),
    "gazebo_ros_planar_move": Family(
        lambda: dm.planar_base(PLANAR), "urdf", "holonomic", {"angular": 0.5, "lateral": 0.1}
    ),
}
V, T = 0.3, 4.0  # [m/s], [s]


def _ramped(goal: float, accel: float, t: float) -> float:
    """The plugin's ramp: towards `goal` at `accel` until T, then back to 0 (inf: a step)."""
    if math.isinf(accel):
        return goal if t < T else 0.0
    if t < T:
        return math.copysign(min(abs(goal), accel * t), goal)
    rest = max(0.0, abs(goal) - accel * (t - T))
    return math.copysign(min(rest, abs(goal)), goal)


def _oracle(family: Family, start: tuple, applied: dict, command: dict) -> tuple[tuple, float]:
    """End pose (x, y, θ) and the distance driven, by the family's kinematic model."""
    x, y, th = start
    ramps = (LINEAR_RAMP, LINEAR_RAMP, ANGULAR_RAMP) if family.model == "holonomic" else None
    goals = (command.get("linear", 0.0), command.get("lateral", 0.0), command.get("angular", 0.0))
    if family.model == "bicycle":
        goals = (applied["speed"], 0.0, applied["yaw_rate"])
    path, t, dt = 0.0, 0.0, 1e-4
    while t < T + SETTLE:
        accel = ramps or (math.inf,) * 3
        vx, vy, w = (_ramped(g, a, t) for g, a in zip(goals, accel, strict=True))
        c, s = math.cos(th), math.sin(th)
        x, y, th = x + (vx * c - vy * s) * dt, y + (vx * s + vy * c) * dt, th + w * dt
        path, t = path + math.hypot(vx, vy) * dt, t + dt
    return (x, y, th), path


def _spawned(tmp_path: Path, name: str, text: str) -> World:
    """A world with `text` (a FAMILIES robot, or a variant of one) spawned on the ground as
    `base`, the files its family needs beside it."""
    family = FAMILIES[name]
    path = tmp_path / f"{name}.{family.suffix}"
    path.write_text(text)
    for file_name, extra in family.files:
        (tmp_path / file_name).write_text(extra)
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    return world


def _drive(tmp_path: Path, name: str, command: dict) -> tuple:
    family = FAMILIES[name]
    world = _spawned(tmp_path, name, family.robot())
    world.step(300)  # settle on the ground [ms]
    if family.model == "bicycle" and "angular" not in command:
        steer = {k: v for k, v in command.items() if k in ("steering", "curvature")}
        drive(world, "base", 0.0, **steer)  # steer in place first: the turn starts turned
        world.step(800)
    start = world.get_pose("base")
    reply = drive(world, "base", duration=T, **command)
    world.step(round((T + SETTLE) / world.model.opt.timestep))
    return world, family, (start.x, start.y, start.yaw), reply


# Turns that leave the kinematic model's path by more than PATH_TOLERANCE, measured.
OFF_PATH = {
    "vendor_kobuki": "its 1 N m wheel torque lets the wheels slip on the turn: 31.7 mm off 1.2 m",
    "gazebo_ros_planar_move": "the planar servo pushes the base at its centre of mass against its "
    "contacts' friction, which tips it at the start and stop: 121 mm off 1.27 m (Gazebo sets the "
    "velocity itself)",
}


def _cases() -> list:
    return [
        pytest.param(name, motion, marks=pytest.mark.xfail(strict=True, reason=OFF_PATH[name]))
        if motion == "turn" and name in OFF_PATH
        else (name, motion)
        for name in sorted(FAMILIES)
        for motion in ("straight", "turn")
    ]


@pytest.mark.parametrize(("name", "motion"), _cases())
def test_drive_follows_its_kinematic_model_and_odometry_the_world_pose(
    tmp_path: Path, name: str, motion: str
) -> None:
    turn = FAMILIES[name].turn if motion == "turn" else {}
    command = {"linear": V, **turn}
    world, family, start, reply = _drive(tmp_path, name, command)
    (x, y, th), path = _oracle(family, start, reply["applied"], command)
    end = world.get_pose("base")
    if family.skid and motion == "turn":
        turned = math.remainder(end.yaw - start[2], 2 * math.pi) / (th - start[2])
        coulomb = turned / dm.COULOMB_FACTOR
        assert 1.0 - dm.COULOMB_SHORT <= coulomb <= 1.0 + dm.COULOMB_OVER, (
            f"{name}: {coulomb:.3f} of Coulomb's turn"
        )
        return
    error = math.hypot(end.x - x, end.y - y)
    assert error <= PATH_TOLERANCE * path, f"{name}: {error:.4f} m off over a {path:.3f} m path"
    turned = abs(th - start[2])
    heading = abs(math.remainder(end.yaw - th, 2 * math.pi))
    allowed = PATH_TOLERANCE * turned if turned > 0.1 else STRAIGHT_HEADING
    assert heading <= allowed, f"{name}: heading {heading:.4f} rad off of a {turned:.3f} rad turn"
    odom = odometry(world, "base")
    ox, oy = odom["pose"]["position"][:2]
    assert math.hypot(ox - end.x, oy - end.y) <= family.odom_tolerance, (
        f"{name}: {odom['source']} odometry ({ox:.4f}, {oy:.4f}) vs world ({end.x:.4f}, "
        f"{end.y:.4f})"
    )


@pytest.mark.parametrize(
    ("name", "command", "needle"),
    [
        ("gazebo_ros_ackermann_drive", {"lateral": 0.1}, "cannot move sideways"),
        ("vendor_kobuki", {"steering": 0.2}, "steered bases"),
        ("gazebo_ros_tricycle_drive", {"angular": 0.2, "curvature": 1.0}, "not both"),
    ],
)
def test_an_option_its_drive_does_not_take_leaves_the_world_unchanged(
    tmp_path: Path, name: str, command: dict, needle: str
) -> None:
    from world_helpers import full_state

    from twin_cli.errors import InvalidRequestError

    family = FAMILIES[name]
    path = tmp_path / f"{name}.{family.suffix}"
    path.write_text(family.robot())
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    before = full_state(world)
    held, watching = dict(world.commands()), set(world._state.observers._entries)
    with pytest.raises(InvalidRequestError, match=needle):
        drive(world, "base", 0.3, **command)
    assert (full_state(world) == before).all(), "state, controls and time unchanged"
    assert dict(world.commands()) == held, "no command but the plugin's hold from load"
    assert set(world._state.observers._entries) == watching, "no command, no controller"


SLOPE = math.radians(5.0)  # gravity tilted along the base's forward axis: a 5° slope
HOLD_SETTLE = 5.0  # [s] on the slope before the watch: a velocity servo learns its load
HELD_M = 1e-3  # [m] a held base moves less than this in a watch (2 s, or 30 s parked)
PARKED = 30.0  # [s] the watch of a base no one has driven


def _watch_on_a_slope(world: World, watch: float = 2.0) -> float:
    """Tilts gravity by SLOPE; how far the base moves in `watch` [s] after HOLD_SETTLE [m]."""
    world.step(300)
    world.set_gravity((9.81 * math.sin(SLOPE), 0.0, -9.81 * math.cos(SLOPE)))
    world.step(round(HOLD_SETTLE / world.model.opt.timestep))
    p0 = world.get_pose("base")
    world.step(round(watch / world.model.opt.timestep))
    p1 = world.get_pose("base")
    return math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z))


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_a_base_no_one_has_driven_holds_on_a_slope(tmp_path: Path, name: str) -> None:
    """Gazebo's drive plugins command their wheels from load, so a parked base stands on a 5°
    slope for 30 s, also after a reset. Control: without its plugins the robot rolls down it
    (>5 cm in 2 s)."""
    world = _spawned(tmp_path, name, FAMILIES[name].robot())
    moved = _watch_on_a_slope(world, PARKED)
    assert moved < HELD_M, f"{name}: moved {moved * 1e3:.3f} mm in {PARKED:g} s on a 5° slope"
    world.reset()
    again = _watch_on_a_slope(world)
    assert again < HELD_M, f"{name}: after a reset, moved {again * 1e3:.3f} mm in 2 s"
    if (
        'type="continuous"' not in FAMILIES[name].robot()
        or "<ros2_control" in FAMILIES[name].robot()
    ):
        return  # a base without wheels stands without its plugin too; tagged wheels are servos
    free = re.sub(r"<plugin\b.*?</plugin>", "", FAMILIES[name].robot(), flags=re.S)
    rolled = _watch_on_a_slope(_spawned(tmp_path, name, free))
    assert rolled > 0.05, f"{name} without its plugins rolled only {rolled:.3f} m: no control"


def test_a_plugin_hold_is_the_wheels_own_motor_at_zero_until_the_first_drive(
    tmp_path: Path,
) -> None:
    """A spawned base's held wheels are their velocity motors (the exported file's rotor and
    friction tendon, bounded by the effort) at speed 0; the drive's commands then write the
    rotors' ctrl and nothing else on the model."""
    import numpy as np

    from twin_cli.world import velocity_motors

    world = _spawned(tmp_path, "gazebo_ros_diff_drive", FAMILIES["gazebo_ros_diff_drive"].robot())
    m, wheels = world.model, ("wheel_left_joint", "wheel_right_joint")
    ids = [m.actuator(f"base/{j}").id for j in wheels]
    motors = [velocity_motors.rotor_of(m, a) for a in ids]
    spin = [r.actuator for r in motors]
    tendons = [r.tendon for r in motors]
    shown = {world.joint_commands("base")[j]["rule"] for j in wheels}
    assert shown == {velocity_motors.RULE}, shown
    assert list(world.data.ctrl[spin]) == [0.0, 0.0], "held: speed 0"
    bound = m.tendon_frictionloss[tendons].copy()
    efforts = [world.joint_commands("base")[j]["effort_limit"] for j in wheels]
    assert list(bound) == pytest.approx(efforts, rel=1e-12), "the bound is the effort limit"
    law = m.actuator_gainprm[ids].copy(), m.actuator_biasprm[ids].copy()
    drive(world, "base", V)
    world.step(100)
    assert all(world.data.ctrl[spin] > 0), "driven: the wheels' speeds are their rotors' ctrl"
    assert np.array_equal(m.actuator_gainprm[ids], law[0]), "gains unchanged"
    assert np.array_equal(m.actuator_biasprm[ids], law[1]), "gains unchanged"
    assert np.array_equal(m.tendon_frictionloss[tendons], bound), "bound unchanged"


def test_the_first_drive_keeps_the_force_the_hold_carried(tmp_path: Path) -> None:
    """Held on a slope, then a first drive command of zero speed: the wheels stay held by their
    friction, so the base does not sag downhill."""
    world = _spawned(tmp_path, "gazebo_ros_diff_drive", FAMILIES["gazebo_ros_diff_drive"].robot())
    assert _watch_on_a_slope(world) < HELD_M
    p0 = world.get_pose("base")
    drive(world, "base", 0.0, angular=0.0)
    world.step(2000)
    p1 = world.get_pose("base")
    moved = math.dist((p0.x, p0.y, p0.z), (p1.x, p1.y, p1.z))
    assert moved < HELD_M, f"sagged {moved * 1e3:.3f} mm when the drive took over the hold"


def test_a_restored_world_without_commands_keeps_the_wheels_own_servos(tmp_path: Path) -> None:
    """A snapshot (or an older save file) that holds no commands is restored as it was: no
    command, and the wheels' own servos, which are the model, hold the base on the slope at
    the ctrl the snapshot kept."""
    world = _spawned(tmp_path, "gazebo_ros_diff_drive", FAMILIES["gazebo_ros_diff_drive"].robot())
    world.restore(dataclasses.replace(world.snapshot(), commands=()))
    assert not world.commands()
    assert _watch_on_a_slope(world) < HELD_M, "the model's servos hold the base"


@pytest.mark.parametrize(("speed", "accel"), [(0.5, 1.0), (1.0, 1.0), (1.0, 2.0)])
def test_ackermann_encoder_odometry_on_a_straight_line_stays_on_the_world_pose(
    tmp_path: Path, speed: float, accel: float
) -> None:
    """gz-sim AckermannSteering's odometry integrates its rear wheels' turns. Driven 5 m
    straight at `speed` with its `max_acceleration` and `min_acceleration` (rates the rear
    wheels' friction can give the car: about half its weight at μ = 1, so below ~4 m/s² no wheel
    slips; without `min_acceleration` the plugin stops the wheels at once and the car slides),
    the odometry stays within 5 mm and 0.005 rad of the world pose, before and after the stop."""
    plugin = GZ_ACKERMANN.replace(
        "</plugin>",
        f"<max_acceleration>{accel}</max_acceleration><min_acceleration>{-accel}"
        "</min_acceleration></plugin>",
    )
    world = _spawned(tmp_path, "gz_ackermann_steering_sdf", dm.sdf_ackermann(plugin))
    world.step(300)
    start, origin = world.get_pose("base"), odometry(world, "base")["pose"]
    duration = 5.0 / speed
    drive(world, "base", speed, duration=duration)
    for seconds in (duration / 2, duration / 2 + speed / accel + 0.5):
        world.step(round(seconds / world.model.opt.timestep))
        end, odom = world.get_pose("base"), odometry(world, "base")["pose"]
        dx, dy = end.x - start.x, end.y - start.y
        ox, oy = (odom["position"][i] - origin["position"][i] for i in (0, 1))
        gap = math.hypot(dx - ox, dy - oy)
        turn = abs(math.remainder((end.yaw - start.yaw) - odom["rpy"][2], 2 * math.pi))
        assert gap < 5e-3, f"odometry {gap * 1e3:.2f} mm from the world pose after {dx:.3f} m"
        assert turn < 5e-3, f"odometry heading {turn:.4f} rad from the world's"
    assert dx == pytest.approx(5.0, rel=0.02), f"drove {dx:.4f} m of 5"


@pytest.mark.parametrize("name", ["gz_diff_drive_sdf", "gz_ackermann_steering_sdf"])
@pytest.mark.parametrize(("x", "y", "yaw"), [(2.0, -1.0, 1.0), (-3.0, 4.0, -2.5)])
def test_encoder_odometry_starts_at_zero_wherever_the_base_was_spawned(
    tmp_path: Path, name: str, x: float, y: float, yaw: float
) -> None:
    """gz-sim's encoder odometry starts at (0, 0, 0) in the frame the base starts in, so after
    a drive it is the world motion seen from the start pose (Gazebo's plugins start at zero)."""
    from twin_cli.world import Pose

    family = FAMILIES[name]
    path = tmp_path / f"{name}.{family.suffix}"
    path.write_text(family.robot())
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base", pose=Pose(x, y, 0, 0, 0, yaw))
    world.step(300)
    first = odometry(world, "base")["pose"]
    assert max(abs(v) for v in (*first["position"], first["rpy"][2])) < 1e-3, first
    start = world.get_pose("base")
    drive(world, "base", 0.3, duration=2.0)
    world.step(2500)
    end, odom = world.get_pose("base"), odometry(world, "base")["pose"]
    c, s = math.cos(start.yaw), math.sin(start.yaw)
    dx, dy = end.x - start.x, end.y - start.y
    seen = (c * dx + s * dy, -s * dx + c * dy)  # the motion in the start frame
    got = odom["position"][:2]
    assert math.dist(got, seen) < ODOM_TOLERANCE, f"odometry {got} vs {seen} from the start"
    assert seen[0] == pytest.approx(0.6, rel=0.05), f"drove {seen[0]:.3f} m ahead"
