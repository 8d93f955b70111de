"""Commands from a joint resting on its limit, taken as ros2_control takes them: the start state
is never refused, and a position at most `LIMIT_TOLERANCE` past the range is clamped onto it.

The arm: one hinge about y, range ±1.7628 rad, its centre of mass above the link's axis so that
gravity holds it against the upper limit (its free rest would be at 2.16 rad). With its effort
interface released it droops onto the limit and MuJoCo's soft limit lets it sink a little past.
"""

from __future__ import annotations

import re

import pytest
from models import write_urdf

from twin_cli.control import Trajectory, TrajectoryPoint, follow_trajectory, tracking_report
from twin_cli.errors import InvalidRequestError
from twin_cli.world import World
from twin_cli.world.joint_control import LIMIT_TOLERANCE

LIMIT = 1.7628  # [rad] the hinge's upper limit (and -LIMIT its lower)
ARM = f"""<robot name="arm">
  <link name="world"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0.3 0 0.2"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-{LIMIT}" upper="{LIMIT}" effort="50" velocity="2"/>
  </joint>
  <ros2_control name="arm" type="system">
    <joint name="shoulder">
      <command_interface name="position"/><command_interface name="effort"/>
    </joint>
  </ros2_control>
</robot>
"""


@pytest.fixture
def drooped(tmp_path) -> World:
    """The arm, its effort released, left 3 s to droop onto its upper limit."""
    from converters import convert

    spec, _ = convert(write_urdf(tmp_path, ARM))
    world = World()
    world.spawn(spec, name="arm")
    world.command_joints("arm", {"shoulder": 0.0}, mode="effort")
    world.step(int(3.0 / world.model.opt.timestep))
    return world


def _shoulder(world: World) -> float:
    return next(s.position for s in world.joint_states("arm") if s.name == "shoulder")


def test_the_arm_droops_just_past_its_limit(drooped) -> None:
    """The premise: gravity leaves the hinge past the limit, within the tolerance."""
    past = _shoulder(drooped) - LIMIT
    assert 0.0 < past < LIMIT_TOLERANCE, f"rests {past:.3e} rad past the limit"


@pytest.mark.parametrize("goal", [1.2, 0.0, -1.0])
def test_a_trajectory_from_an_arm_resting_past_its_limit_reaches_its_goal(drooped, goal) -> None:
    """Every waypoint inside the range, the start outside it: accepted and followed; 0.5 s
    after its end the hinge is within 2 mrad of the goal (measured: 3e-5 to 1.6e-4 rad; the
    arm rested 4.9e-9 rad past the limit; final tracking error at 2 s 3e-4 to 3.5e-3 rad)."""
    start = _shoulder(drooped)
    middle = (start + goal) / 2
    trajectory = Trajectory(
        ("shoulder",), (TrajectoryPoint(1.0, (middle,)), TrajectoryPoint(2.0, (goal,)))
    )
    follow_trajectory(drooped, "arm", trajectory)
    drooped.step(int(2.5 / drooped.model.opt.timestep))
    report = tracking_report(drooped, "arm")
    assert report is not None and not report["active"], "the follower finished at 2 s"
    assert report["clamped"] == {}, "no waypoint was outside the range"
    error = abs(_shoulder(drooped) - goal)
    assert error < 2e-3, f"{error:.2e} rad from the goal {goal} rad, 0.5 s after the end"
    assert report["final_error"]["shoulder"] < 0.02, report["final_error"]


@pytest.mark.parametrize("past", [1e-8, 1e-3, 0.008])
def test_a_waypoint_just_past_the_limit_is_clamped_onto_it_and_reported(drooped, past) -> None:
    trajectory = Trajectory(("shoulder",), (TrajectoryPoint(1.0, (LIMIT + past,)),))
    follow_trajectory(drooped, "arm", trajectory)
    drooped.step(int(1.5 / drooped.model.opt.timestep))
    report = tracking_report(drooped, "arm")
    assert report is not None
    assert report["clamped"]["shoulder"] == pytest.approx(past, abs=1e-12), report["clamped"]
    held = {c.actuator.split("/")[1]: c for c in drooped.commands().values()}
    # the servo reference ends within its own settling (measured 1e-8 rad) of the target
    assert held["shoulder"].target == pytest.approx(LIMIT, abs=1e-6), "held on the limit"


@pytest.mark.parametrize("past", [0.01, 0.5])
def test_a_waypoint_further_past_the_limit_is_refused_naming_the_range(drooped, past) -> None:
    trajectory = Trajectory(("shoulder",), (TrajectoryPoint(1.0, (LIMIT + past,)),))
    with pytest.raises(InvalidRequestError, match=re.escape(f"outside [-{LIMIT}, {LIMIT}]")):
        follow_trajectory(drooped, "arm", trajectory)


@pytest.mark.parametrize(("value", "held"), [(LIMIT + 1.3e-8, LIMIT), (-LIMIT - 0.008, -LIMIT)])
def test_a_position_command_just_past_a_limit_is_clamped_onto_it(drooped, value, held) -> None:
    (command,) = drooped.command_joints("arm", {"shoulder": value}, mode="position")
    assert command.target == pytest.approx(held, abs=1e-12), "target clamped onto the limit"


def test_a_position_command_further_past_a_limit_is_still_refused(drooped) -> None:
    with pytest.raises(InvalidRequestError, match=re.escape("outside [-1.7628, 1.7628]")):
        drooped.command_joints("arm", {"shoulder": LIMIT + 0.01}, mode="position")
