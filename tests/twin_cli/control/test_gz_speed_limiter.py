"""gz-sim's DiffDrive limits the commanded twist, not the wheels: its linear and angular
SpeedLimiters bound the change of v and of ω on their own, each between its signed
`min_*_acceleration` and `max_*_acceleration` (`min_acceleration`/`max_acceleration` set both),
and a bound no tag sets is none. A model that gives only `max_linear_acceleration` (turtlebot3's
gz-sim models) speeds up at that rate and stops at once.

Robot written here: the two-wheel base of the drive tests (tests/drive_models.py, frictionless
casters) as an SDF model. Oracle: the limiter's bounds applied to the command in closed form
(a ramp of slope a for |goal|/a, a step where unbounded), the base's travel and turn from them;
bound: PATH_TOLERANCE of the distance or of the turn, the drive families' bound.
"""

from __future__ import annotations

import math
from pathlib import Path

import drive_models as dm
import pytest

from twin_cli.control import drive
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import World

PATH_TOLERANCE = 0.02  # fraction of the distance driven or of the turn
T = 4.0  # [s] the command's duration
SETTLE = 4.5  # [s] stepped after it: the slowest stop ramp here (1 rad/s at 0.25 rad/s²) ends


def _gz_diff(limits: str) -> str:
    return (
        '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">'
        "<left_joint>wheel_left_joint</left_joint><right_joint>wheel_right_joint</right_joint>"
        "<wheel_separation>0.3</wheel_separation><wheel_radius>0.05</wheel_radius>"
        f"{limits}</plugin>"
    )


def _run(tmp_path: Path, limits: str, linear: float, angular: float) -> tuple[float, float]:
    """Distance [m] along the start heading and turn [rad] (unwrapped) of the base."""
    path = tmp_path / "base.sdf"
    path.write_text(dm.sdf_diff_drive(_gz_diff(limits)))
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.step(300)
    start = world.get_pose("base")
    drive(world, "base", linear, angular, T)
    turned, last = 0.0, start.yaw
    for _ in range(round((T + SETTLE) / 0.01)):
        world.step(10)
        yaw = world.get_pose("base").yaw
        turned, last = turned + math.remainder(yaw - last, 2 * math.pi), yaw
    end = world.get_pose("base")
    along = (end.x - start.x) * math.cos(start.yaw) + (end.y - start.y) * math.sin(start.yaw)
    return along, turned


def _travel(goal: float, rise: float, fall: float) -> float:
    """∫ of a command `goal` held for T under the bounds: ramps of `rise` up and `fall` down
    [per s²] (inf: a step), the stop ramp after T included."""
    up = goal * (T - goal / (2 * rise)) if math.isfinite(rise) else goal * T
    return up + (goal * goal / (2 * fall) if math.isfinite(fall) else 0.0)


@pytest.mark.parametrize(
    ("limits", "rise", "fall"),
    [
        ("<max_linear_acceleration>0.5</max_linear_acceleration>", 0.5, math.inf),
        ("<max_acceleration>0.5</max_acceleration>"
         "<min_acceleration>-0.25</min_acceleration>", 0.5, 0.25),
        ("<max_linear_acceleration>0.5</max_linear_acceleration>"
         "<min_linear_acceleration>-0.5</min_linear_acceleration>", 0.5, 0.5),
    ],
)  # fmt: skip
def test_the_forward_speed_changes_within_its_signed_bounds(
    tmp_path: Path, limits: str, rise: float, fall: float
) -> None:
    """0.3 m/s for 4 s: 1.11 m when only the rise is bounded (the base stops at once), 1.29 m
    when the fall is half as steep, 1.2 m when both are 0.5 m/s²."""
    along, turned = _run(tmp_path, limits, 0.3, 0.0)
    expected = _travel(0.3, rise, fall)
    assert along == pytest.approx(expected, rel=PATH_TOLERANCE), f"{along:.4f} m of {expected}"
    assert abs(turned) < 0.02, "a straight line"


@pytest.mark.parametrize(
    ("limits", "rise", "fall"),
    [
        ("<max_angular_acceleration>0.5</max_angular_acceleration>", 0.5, math.inf),
        ("<max_linear_acceleration>0.1</max_linear_acceleration>", math.inf, math.inf),
        ("<max_acceleration>0.5</max_acceleration>"
         "<min_acceleration>-0.25</min_acceleration>", 0.5, 0.25),
    ],
)  # fmt: skip
def test_the_yaw_rate_changes_within_its_own_bounds(
    tmp_path: Path, limits: str, rise: float, fall: float
) -> None:
    """1 rad/s in place for 4 s: 3 rad when ω rises at 0.5 rad/s² and stops at once, 4 rad when
    only the linear speed is bounded (ω is not: the wheels' rims reach ±0.15 m/s at once),
    5 rad when it also falls at 0.25 rad/s²."""
    along, turned = _run(tmp_path, limits, 0.0, 1.0)
    expected = _travel(1.0, rise, fall)
    message = f"{turned:.4f} rad of {expected}"
    assert turned == pytest.approx(expected, rel=PATH_TOLERANCE), message
    assert abs(along) < 0.01, "in place"


@pytest.mark.parametrize(
    ("limits", "linear", "expected"),
    [
        ("<max_linear_velocity>0.2</max_linear_velocity>", 0.3, 0.2 * T),
        ("<max_linear_velocity>0.2</max_linear_velocity>", -0.3, -0.3 * T),  # no min: none
        ("<max_velocity>0.2</max_velocity><min_velocity>-0.1</min_velocity>", -0.3, -0.1 * T),
    ],
)
def test_speed_bounds_are_signed_and_an_unset_one_is_none(
    tmp_path: Path, limits: str, linear: float, expected: float
) -> None:
    """gz-sim clamps v between min_linear_velocity and max_linear_velocity (min_velocity and
    max_velocity set both of v's and ω's), and a bound no tag sets is none: a base whose
    maximum is 0.2 m/s reverses at the 0.3 m/s asked."""
    along, _ = _run(tmp_path, limits, linear, 0.0)
    assert along == pytest.approx(expected, rel=PATH_TOLERANCE), f"{along:.4f} m of {expected}"


def test_max_velocity_bounds_the_yaw_rate_too(tmp_path: Path) -> None:
    """`max_velocity` 0.5 caps ω at 0.5 rad/s as well: 2 rad in 4 s for 1 rad/s asked."""
    _, turned = _run(tmp_path, "<max_velocity>0.5</max_velocity>", 0.0, 1.0)
    assert turned == pytest.approx(0.5 * T, rel=PATH_TOLERANCE), f"{turned:.4f} rad"
