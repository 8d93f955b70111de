"""gz-sim's AckermannSteering as its update runs: steering by proportional speed commands, and
one pair of speed limiters bounding the forward speed and the yaw rate alike.

Each update the system commands every steering joint the speed g·(θ* − θ), g its
`steer_p_gain` (default 1/s), so a steered wheel closes on its Ackermann angle θ* as the first-order
lag θ*(1 − e^(−g·t)), not at once. Its limiters take `min_velocity`/`max_velocity` and
`min_acceleration`/`max_acceleration` for v and ω alike; a bound no tag sets is none, so a car with
`max_acceleration` alone speeds up at that rate and stops at the first update after the command
ends.

Oracles: the closed-form lag above for the joints' angles (the car is the SDF car of
`drive_models.sdf_ackermann`, whose steering joints allow 50 N m, far above what turning a
0.1 kg knuckle and its wheel takes); the yaw-rate bound of the reply against the bicycle model.
"""

from __future__ import annotations

import math
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import drive
from twin_cli.control.steering import ackermann_angles
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

PLUGIN = (
    '<plugin filename="gz-sim-ackermann-steering-system" '
    'name="gz::sim::systems::AckermannSteering"><left_joint>rear_left_joint</left_joint>'
    "<right_joint>rear_right_joint</right_joint><left_steering_joint>left_steering_joint"
    "</left_steering_joint><right_steering_joint>right_steering_joint</right_steering_joint>"
    f"<kingpin_width>{dm.TRACK}</kingpin_width><steering_limit>0.6</steering_limit><wheel_base>"
    f"{dm.WHEEL_BASE}</wheel_base><wheel_separation>{dm.TRACK}</wheel_separation><wheel_radius>"
    f"{dm.R}</wheel_radius>{{tags}}</plugin>"
)
V, OMEGA = 0.5, 0.4  # [m/s], [rad/s]: a 1.25 m radius, inside the 0.6 rad steering limit
# [rad] angle error allowed against the lag law: the joint's velocity servo follows a changing
# speed command about 30 ms behind (measured; Gazebo's velocity constraint: one step), which at
# g = 4/s puts the joint 0.015 rad behind the law at 0.25 s and 0.006 rad at 0.5 s.
ANGLE_TOLERANCE = 0.02


def _car(tmp_path: Path, tags: str) -> World:
    path = tmp_path / "car.sdf"
    path.write_text(dm.sdf_ackermann(PLUGIN.format(tags=tags)))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="car")
    world.step(300)  # [ms] settle on the ground
    return world


def _angle(world: World, joint: str) -> float:
    return next(j.position for j in world.joint_states("car") if j.name == joint)


@pytest.mark.parametrize("gain", [None, 4.0])
def test_steering_closes_on_its_angle_as_a_first_order_lag(tmp_path: Path, gain: float | None):
    """The left and right steering joints follow θ*(1 − e^(−g·t)) at 0.25-1.5 s, for the
    default gain 1/s and for 4/s; a position servo would reach θ* within a few tenths of a
    second whatever the gain."""
    g = 1.0 if gain is None else gain
    world = _car(tmp_path, "" if gain is None else f"<steer_p_gain>{gain}</steer_p_gain>")
    drive(world, "car", V, OMEGA, duration=2.0)
    start = float(world.data.time)
    phi = math.atan(dm.WHEEL_BASE * OMEGA / V)
    angles = ackermann_angles(phi, dm.WHEEL_BASE, dm.TRACK)
    targets = dict(zip(("left", "right"), angles, strict=True))
    for t in (0.25, 0.5, 1.0, 1.5):
        world.step(round((start + t - float(world.data.time)) / world.model.opt.timestep))
        for side, target in targets.items():
            expected = target * (1.0 - math.exp(-g * t))
            got = _angle(world, f"{side}_steering_joint")
            assert got == pytest.approx(expected, abs=ANGLE_TOLERANCE), (
                f"g {g:g}/s, t {t} s: {side} steering at {got:.4f} rad, the lag law "
                f"{expected:.4f} rad (target {target:.4f})"
            )


def test_max_velocity_bounds_the_yaw_rate_too(tmp_path: Path) -> None:
    """One `max_velocity` bounds v and ω: 0.3 rad/s asked at 0.5 m/s with max_velocity 0.2
    turns at 0.2 rad/s with v at 0.2 m/s, the car's heading rate measured over 2 s."""
    world = _car(tmp_path, "<max_velocity>0.2</max_velocity><steer_p_gain>20</steer_p_gain>")
    reply = drive(world, "car", 0.5, 0.3, duration=4.0)
    assert reply["applied"]["speed"] == pytest.approx(0.2)
    assert reply["applied"]["yaw_rate"] == pytest.approx(0.2, rel=1e-6)
    world.step(1000)  # steering settled (e^-20)
    before = world.get_pose("car").yaw
    world.step(2000)
    rate = math.remainder(world.get_pose("car").yaw - before, 2 * math.pi) / 2.0
    assert rate == pytest.approx(0.2, rel=0.05), f"turned at {rate:.4f} rad/s"


@pytest.mark.parametrize(("bounds", "oracle"), [("", 0.0), ("<min_acceleration>-0.5", 0.25)])
def test_an_unset_deceleration_bound_stops_the_wheels_at_once(
    tmp_path: Path, bounds: str, oracle: float
) -> None:
    """0.5 m/s with `max_acceleration` 0.5: with no `min_acceleration` the wheels stop at the
    first update after the command and the car slides at most v²/(2μg) = 13 mm (μ = 1); with
    `min_acceleration` −0.5 it rolls to a stop over v²/(2a) = 0.25 m. A ramp down at
    `max_acceleration` would roll 0.25 m in both. Bounds: 50 mm for the stop (measured 35 mm:
    the wheels' velocity servos take about 0.1 s to stop them, where Gazebo's velocity
    constraint takes a step); 10 % for the roll, the servos lagging the ramp by about 36 ms
    (18 mm at 0.5 m/s)."""
    tags = "<max_acceleration>0.5</max_acceleration>" + (
        f"{bounds}</min_acceleration>" if bounds else ""
    )
    world = _car(tmp_path, tags)
    drive(world, "car", 0.5, duration=2.0)
    world.step(2000)  # 1 s ramp up, 1 s at 0.5 m/s
    start = world.get_pose("car")
    world.step(1500)
    end = world.get_pose("car")
    rolled = math.hypot(end.x - start.x, end.y - start.y)
    if oracle == 0.0:
        assert rolled < 0.05, f"rolled {rolled:.4f} m after the command's end"
    else:
        assert rolled == pytest.approx(oracle, rel=0.10), f"rolled {rolled:.4f} m of {oracle}"
