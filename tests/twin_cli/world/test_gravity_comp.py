"""Fixed-base robots hold their weight through MuJoCo's gravity compensation, and a loaded joint's
velocity servo holds its speed up to its effort limit. Oracles: the commanded posture (a held
arm does not sag), the commanded speed, and the effort limit (the force beyond it)."""

from __future__ import annotations

import numpy as np
import pytest
from arm_models import bob_arm
from interface_models import PANDA_JOINTS, panda_arm
from models import write_urdf

from twin_cli.world import Pose, World

HOLD_RAD = 1e-3  # [rad] a held posture stays this close to its target, and still, for 5 s
SPEED_TOLERANCE = 0.01  # fraction of the commanded speed a loaded joint keeps
EFFORT = 5.0  # [N m] the one-joint arm's effort limit
REACH = 0.2  # [m] the arm's mass sits this far out on its hinge


def _panda(tmp_path) -> World:
    from converters import convert

    spec, _ = convert(write_urdf(tmp_path, panda_arm(), "panda.urdf"))
    world = World()
    world.spawn(spec, name="panda", pose=Pose())
    return world


def _positions(world: World, name: str) -> np.ndarray:
    return np.array([s.position for s in world.joint_states(name)])


@pytest.mark.parametrize(
    "posture",
    [
        (0.0, 1.5, 0.0, -0.1, 0.0, 1.6, 0.0),  # stretched out horizontally
        (0.0, 0.9, 0.0, -0.3, 0.0, 1.5, 0.0),
        (0.5, 1.2, -0.5, -0.8, 0.5, 2.0, 0.3),
    ],
)
def test_a_fixed_arm_holds_a_posture_under_gravity_within_a_milliradian(tmp_path, posture):
    """Position servos on a Panda (7 joints, fixed base) hold a posture against its weight:
    MuJoCo's gravcomp sends the load through each joint's actuator, so the servos' error is not
    load/kp (joint 2 of the stretched arm: 9 mrad with kp alone)."""
    world = _panda(tmp_path)
    world.command_joints("panda", dict(zip(PANDA_JOINTS, posture, strict=True)), mode="position")
    world.step(4000)  # the moves (at most 1.6 rad at 2.175 rad/s and above) and their settling
    start = _positions(world, "panda")
    assert np.abs(start - posture).max() < HOLD_RAD, f"settled at {start - posture}"
    drift = 0.0
    for _ in range(50):  # 5 s
        world.step(100)
        drift = max(drift, float(np.abs(_positions(world, "panda") - start).max()))
    assert drift < HOLD_RAD, f"moved {drift * 1e3:.3f} mrad in 5 s"


def _swing(tmp_path, load: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The arm with a weight of `load` × EFFORT at horizontal, commanded at -0.3 rad/s from 0.3
    rad (through horizontal): its speed, motor force and angle every 10 ms for 2 s after 0.5 s."""
    world = World()
    mass = load * EFFORT / (9.81 * REACH)
    world.spawn(write_urdf(tmp_path, bob_arm(EFFORT, mass, REACH)), name="a", pose=Pose(z=1.0))
    world.command("a", "j", mode="position", value=0.3)
    world.step(2000)
    world.command("a", "j", mode="velocity", value=-0.3)
    world.step(500)
    speeds, forces, angles = [], [], []
    for _ in range(200):
        world.step(10)
        speeds.append(world.joint_states("a")[0].velocity)
        angles.append(world.joint_states("a")[0].position)
        forces.append(float(world.data.actuator_force[0]))
    return np.array(speeds), np.array(forces), np.array(angles)


@pytest.mark.parametrize("load", [0.2, 0.5, 0.9])
def test_a_loaded_joint_keeps_its_commanded_speed_within_its_effort(tmp_path, load):
    """Up to its effort limit the velocity servo's integral carries the weight (0.04 % off
    measured at 0.9 of the effort, the weight changing with the angle as it swings)."""
    speeds, forces, angles = _swing(tmp_path, load)
    assert np.abs(speeds + 0.3).max() < SPEED_TOLERANCE * 0.3, f"speeds {speeds.min():.4f}.."
    # At a steady speed the motor balances the weight's torque m·g·REACH·cos q (Newton).
    weight = load * EFFORT * np.cos(angles)
    assert np.abs(np.abs(forces) - weight).max() < 0.02 * EFFORT, "force against m·g·r·cos q"


@pytest.mark.parametrize("load", [1.2, 1.5, 3.0])
def test_an_overloaded_joint_gives_exactly_its_effort(tmp_path, load):
    """Past its effort limit the joint falls with its motor at exactly the limit: commanded at
    -0.3 rad/s from horizontal, it falls the other way while the weight's torque exceeds the
    effort (0.2 s: at most 0.63 rad, within arccos(1/load) of horizontal)."""
    world = World()
    mass = load * EFFORT / (9.81 * REACH)
    world.spawn(write_urdf(tmp_path, bob_arm(EFFORT, mass, REACH)), name="a", pose=Pose(z=1.0))
    world.command("a", "j", mode="velocity", value=-0.3)
    world.step(50)
    forces = []
    for _ in range(150):
        world.step(1)
        forces.append(float(world.data.actuator_force[0]))
    assert world.joint_states("a")[0].velocity > 0.0, "it falls"
    assert forces == pytest.approx([-EFFORT] * len(forces), abs=1e-9), f"{min(forces)}.."


def test_an_mjcf_position_servo_is_not_bounded_by_its_position_range(tmp_path):
    """A hand-written fixed arm whose `<position>` servo has ctrlrange ±1.5 rad (a range of
    targets, not of force) holds a 2.45 N m weight at 0.3 rad: the compensation's bound is the
    actuator's force range (none here), not its control range (bounded by it, the arm fell to
    0.76 rad). The World runs the file's own servo (kp 200, kv 10): uncompensated, it would sag
    2.45/200 = 12 mrad."""
    path = tmp_path / "servo_arm.xml"
    path.write_text(
        """<mujoco model="servo_arm"><worldbody><body name="base" pos="0 0 1">
  <geom type="box" size="0.05 0.05 0.05" mass="1" contype="0" conaffinity="0"/>
  <body name="link"><joint name="shoulder" type="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03" mass="1" contype="0"
      conaffinity="0"/></body></body></worldbody>
  <actuator><position name="shoulder" joint="shoulder" kp="200" kv="10" ctrlrange="-1.5 1.5"
      ctrllimited="true"/></actuator></mujoco>"""
    )
    world = World()
    world.spawn(path, name="servo_arm", pose=Pose())
    world.command("servo_arm", "shoulder", mode="position", value=0.3)
    world.step(6000)
    angle = world.joint_states("servo_arm")[0].position
    assert angle == pytest.approx(0.3, abs=HOLD_RAD), f"at {angle:.4f} rad"
