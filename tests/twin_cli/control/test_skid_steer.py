"""A skid steer in a world. Its wheels (`converters.gazebo.skid_wheels`, with the contacts the drive
softens while it turns, `twin_cli.control.skid_contacts`): driven at fixed speeds, the base turns
as Coulomb friction says, ω/(1 + (a/c)²) for wheels run at the unicycle's speeds
(a half the wheel base, c half the track, equal loads). Its loops (`twin_cli.control.skid_trim`,
the controller's side): a stopped base is left where it is put, and the loops' corrections obey
the plugin's wheel acceleration. Robots the tests write (tests/drive_models.py)."""

from __future__ import annotations

import math
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import drive
from twin_cli.control.drives import controller_of
from twin_cli.control.skid_contacts import TURN_IMPEDANCE, WheelContacts
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World
from twin_cli.world.engine import Pose

ACCEL = 1.0  # [m/s² at the rim]
COULOMB_TOLERANCE = 0.1  # of the predicted turn rate (measured -1.5 % to -7.4 %; -62 % to -79 %
# with the rigid, light wheels before)
SKID_ROS2 = (
    '<plugin name="dd4" filename="libgazebo_ros_diff_drive.so"><num_wheel_pairs>2'
    "</num_wheel_pairs><left_joint>left_front_joint</left_joint><right_joint>right_front_joint"
    "</right_joint><left_joint>left_rear_joint</left_joint><right_joint>right_rear_joint"
    "</right_joint><wheel_separation>0.3</wheel_separation><wheel_separation>0.3"
    "</wheel_separation><wheel_diameter>0.1</wheel_diameter><wheel_diameter>0.1</wheel_diameter>"
    f"<max_wheel_torque>5</max_wheel_torque><max_wheel_acceleration>{ACCEL}"
    "</max_wheel_acceleration></plugin>"
)


def _skid_world(tmp_path: Path) -> World:
    path = tmp_path / "skid.urdf"
    path.write_text(dm.skid_steer_bot(SKID_ROS2))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.step(300)
    return world


def test_a_stopped_skid_steer_is_left_where_it_is_put(tmp_path: Path) -> None:
    world = _skid_world(tmp_path)
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(3000)  # the turn, its ramp down and the 1 s hold after it
    controller = controller_of(world, "base")
    pose = world.get_pose("base")
    moved = Pose(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw + 0.05)  # a nudge
    world.set_pose("base", moved)
    written = dict(world.commands())
    world.step(2000)
    after = world.get_pose("base")
    turned = abs(math.remainder(after.yaw - moved.yaw, 2 * math.pi))
    assert turned < 1e-3, f"turned back {turned:.4f} rad after a set pose on a stopped base"
    assert dict(world.commands()) == written, "no wheel target written while it stands"
    assert controller.observed_rate == controller.plugin_rate, "back at the plugin's rate"


def test_the_loops_corrections_obey_the_wheel_acceleration(tmp_path: Path) -> None:
    world = _skid_world(tmp_path)
    start = world.get_pose("base").yaw
    drive(world, "base", 0.0, angular=0.5, duration=2.0)
    controller = controller_of(world, "base")
    rims, steps, worst = controller.written, 0, 0.0
    while steps < 3000:
        world.step(4)  # one update at 250 Hz
        steps += 4
        written = controller.written
        worst = max(worst, *(abs(a - b) for a, b in zip(written, rims, strict=True)))
        rims = written
    assert worst <= ACCEL * 0.004 * (1 + 1e-9), f"a rim speed stepped {worst:.5f} m/s in 4 ms"
    turned = math.remainder(world.get_pose("base").yaw - start, 2 * math.pi)
    assert turned == pytest.approx(1.0, abs=0.01), f"turned {turned:.4f} rad of 1.0"
    assert controller.trim is not None and controller.trim.chi > 1.0, "χ learned, not wound down"


def test_a_skid_steer_moved_while_it_turns_turns_on_from_where_it_was_put(tmp_path: Path) -> None:
    """A set pose is not heading owed: the turn goes on from the new heading."""
    world = _skid_world(tmp_path)
    drive(world, "base", 0.0, angular=0.5, duration=3.0)
    world.step(1000)
    pose = world.get_pose("base")
    world.set_pose("base", Pose(pose.x, pose.y, pose.z, pose.roll, pose.pitch, pose.yaw + 0.5))
    world.step(3000)  # the other 2 s of the turn and the hold after it
    turned = math.remainder(world.get_pose("base").yaw - (pose.yaw + 0.5), 2 * math.pi)
    assert turned == pytest.approx(1.0, abs=0.02), f"turned {turned:.4f} rad of 1.0 after the move"


@pytest.mark.parametrize("wheelbase", [0.12, 0.2, 0.3])
def test_wheels_at_the_unicycles_speeds_turn_the_base_as_coulomb_friction_does(
    tmp_path: Path, wheelbase: float
) -> None:
    path = tmp_path / "skid.urdf"
    path.write_text(dm.skid_steer_bot(dm.SKID_STEER_ROS1, wheelbase=wheelbase))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.step(300)
    v, omega, c, a = 0.3, 0.5, dm.TRACK / 2, wheelbase / 2
    left, right = (v - omega * c) / dm.R, (v + omega * c) / dm.R
    wheels = {"left_front_joint": left, "left_rear_joint": left}
    wheels |= {"right_front_joint": right, "right_rear_joint": right}
    WheelContacts(world, "base", tuple(wheels)).soften()  # as the drive does while it turns
    world.command_joints("base", wheels, mode="velocity")
    world.step(1000)  # the turn set in
    turned, last = 0.0, world.get_pose("base").yaw
    for _ in range(30):
        world.step(100)
        yaw = world.get_pose("base").yaw
        turned, last = turned + math.remainder(yaw - last, 2 * math.pi), yaw
    rate, coulomb = turned / 3.0, omega / (1 + (a / c) ** 2)
    assert rate == pytest.approx(coulomb, rel=COULOMB_TOLERANCE), (
        f"a/c {a / c:.2f}: turns at {rate:.4f} rad/s, Coulomb friction {coulomb:.4f}"
    )


def test_the_loop_starts_from_coulombs_track_multiplier(tmp_path: Path) -> None:
    """1 + (a/c)² of the wheels' layout (a = 0.06 m, c = 0.15 m): nothing to learn at the start."""
    world = _skid_world(tmp_path)
    trim = controller_of(world, "base").trim
    assert trim is not None and trim.chi == pytest.approx(1 + (0.06 / 0.15) ** 2, rel=1e-6)


def test_a_parked_skid_steer_holds_on_a_slope_and_its_wheels_soften_only_in_a_turn(
    tmp_path: Path,
) -> None:
    """Soft contacts creep under a steady load ((1 - d)/B): a parked base's wheels are the
    converter's rigid ones. Oracle: a base held by its wheels on a 10° slope below its friction
    angle (μ 1) stays where it is."""
    world = _skid_world(tmp_path)
    rigid = _wheel_impedance(world)
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(500)
    assert max(_wheel_impedance(world)) <= TURN_IMPEDANCE, "soft while it turns"
    world.step(2500)  # the rest of the turn, its hold, then parked
    assert _wheel_impedance(world) == rigid, "rigid again once parked"
    slope = math.radians(10.0)
    world.set_gravity((-9.81 * math.sin(slope), 0.0, -9.81 * math.cos(slope)))
    world.step(2000)
    before = world.get_pose("base")
    world.step(10000)
    after = world.get_pose("base")
    slid = math.hypot(after.x - before.x, after.y - before.y)
    assert slid < 1e-3, f"slid {slid * 1e3:.3f} mm down a 10° slope in 10 s"


def _wheel_impedance(world: World) -> list[float]:
    m = world.model
    bodies = {m.body(f"base/{w}").id for w in ("left_front", "left_rear")}
    bodies |= {m.body(f"base/{w}").id for w in ("right_front", "right_rear")}
    return [float(m.geom_solimp[g, 0]) for g in range(m.ngeom) if m.geom_bodyid[g] in bodies]


def test_a_spawn_while_it_turns_keeps_its_wheels_soft_then_rigid(tmp_path: Path) -> None:
    """A spawn recompiles the world's model from the robots' specs (rigid wheels)."""
    world = _skid_world(tmp_path)
    rigid = _wheel_impedance(world)
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(300)
    box = tmp_path / "box.urdf"
    box.write_text(
        '<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01" '
        'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
        '<box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
    )
    world.spawn(SpawnRequest(str(box), on_ground=True), name="box", pose=Pose(x=2.0))
    world.step(100)
    assert max(_wheel_impedance(world)) <= TURN_IMPEDANCE, "softened again on the new model"
    world.step(3000)
    assert _wheel_impedance(world) == rigid


def test_straight_after_a_turn_is_rigid_and_a_delete_mid_turn_leaves_no_soft_contact(
    tmp_path: Path,
) -> None:
    """Soft only while the command turns the base; a delete that shifts every geom id mid-turn
    leaves the world's contacts exactly those of a world that never turned."""
    box = tmp_path / "box.urdf"
    box.write_text(
        '<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01" '
        'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
        '<box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
    )
    path = tmp_path / "skid.urdf"
    path.write_text(dm.skid_steer_bot(SKID_ROS2))
    world, fresh = World(), World()
    world.spawn(SpawnRequest(str(box), on_ground=True), name="box", pose=Pose(x=-2.0))
    for w in (world, fresh):
        w.spawn(SpawnRequest(str(path), on_ground=True), name="base")
        w.step(300)
    rigid = _wheel_impedance(world)
    drive(world, "base", 0.2, angular=0.5)
    world.step(500)
    assert max(_wheel_impedance(world)) <= TURN_IMPEDANCE
    drive(world, "base", 0.2, angular=0.0, duration=1.0)
    world.step(100)
    assert _wheel_impedance(world) == rigid, "rigid again on a straight line"
    drive(world, "base", 0.0, angular=0.5, duration=1.0)
    world.step(1200)  # stopped, in the hold after the turn: soft, and no update softens again
    assert max(_wheel_impedance(world)) <= TURN_IMPEDANCE
    world.delete("box")  # every geom of `base` moves down the model's arrays
    world.step(3000)
    assert (world.model.geom_solimp == fresh.model.geom_solimp).all()
