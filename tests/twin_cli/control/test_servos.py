"""Joint servos against Gazebo's joint motor: a velocity held under load while the effort limit
allows, saturation at that limit beyond it, a zero command that holds, and position moves at the
velocity limit without overshoot. Oracles: the commanded values, Newton's law on the disc
(I·dω/dt = load − effort when overloaded), and the move's own geometry (Δ/v)."""

from __future__ import annotations

import numpy as np
import pytest
from arm_models import bob_arm
from models import _control_inertial, write_urdf

from twin_cli.world import Pose, World

EFFORT = 0.1  # [N m] the wheel's effort limit
MOMENT = 1e-3  # [kg m²] the disc's moment about its axle
SPEED = 3.0  # [rad/s] the command


def _wheel(moment: float = MOMENT) -> str:
    """A disc on a continuous joint 'spin' (effort EFFORT, 10 rad/s) above a fixed base."""
    return f"""<robot name="w"><link name="world"/>
<link name="base">{_control_inertial(1, 1)}</link>
<link name="disc">{_control_inertial(0.2, moment)}</link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
  <axis xyz="0 0 1"/><limit effort="{EFFORT}" velocity="10"/></joint>
<ros2_control name="r" type="system"><joint name="spin">
  <command_interface name="velocity"/><command_interface name="position"/>
</joint></ros2_control></robot>"""


def _speeds(world: World, n: int, every: int = 10) -> np.ndarray:
    out = []
    for _ in range(n):
        world.step(every)
        out.append(world.joint_states("w")[0].velocity)
    return np.array(out)


def _load(world: World, torque: float) -> None:
    """A torque [N m] about the axle on the disc, held (a push that outlasts the test)."""
    world.push("w", torque=(0.0, 0.0, torque), link="disc", duration=1e3)


@pytest.fixture
def wheel(tmp_path) -> World:
    world = World()
    world.spawn(write_urdf(tmp_path, _wheel()), name="w", pose=Pose(z=1.0))
    world.command("w", "spin", mode="velocity", value=SPEED)
    world.step(500)
    return world


def test_a_wheel_holds_its_speed_under_half_its_effort_limit(wheel: World) -> None:
    _load(wheel, -EFFORT / 2)
    speeds = _speeds(wheel, 100)  # 1 s
    assert speeds[-50:] == pytest.approx(SPEED, rel=0.01), f"last 0.5 s: {speeds[-50:]}"
    assert speeds.min() > 0.9 * SPEED, f"dipped to {speeds.min():.3f} rad/s when loaded"


def test_an_overloaded_wheel_saturates_at_its_effort_and_comes_back_without_paying_back(wheel):
    """Overloaded, the wheel decelerates as Newton's law with the effort at its limit says.
    Released, it speeds up at effort/I back to its command and runs on from where it is, as
    Gazebo's motor (a velocity constraint bounded by FMax) does: nothing stored, so it ends
    behind its path by the slip alone, Δv²/(2·a_stall) + Δv²/(2·a_back), Δv the speed lost
    (an integral servo paid it back: 43 rad/s peak, back on its path 3.3 s after the release)."""
    q0, t0 = wheel.joint_states("w")[0].position, float(wheel.data.time)
    load = -1.5 * EFFORT
    _load(wheel, load)
    speeds = _speeds(wheel, 50)  # 0.5 s: decelerates at (load + effort)/I
    slope = np.polyfit(np.arange(10, 50) * 0.01, speeds[10:], 1)[0]
    assert slope == pytest.approx((load + EFFORT) / MOMENT, rel=0.02), "I·dω/dt = load + effort"
    _load(wheel, -load)  # the load removed (the pushes add up to 0)
    after = _speeds(wheel, 400)
    assert after[-20:] == pytest.approx(SPEED, rel=0.01), "back at its speed within 4 s"
    lost = SPEED - speeds[-1]
    slip = lost**2 / (2 * -(load + EFFORT) / MOMENT) + lost**2 / (2 * EFFORT / MOMENT)
    behind = q0 + SPEED * (float(wheel.data.time) - t0) - wheel.joint_states("w")[0].position
    assert behind == pytest.approx(slip, rel=0.01), f"{behind:.4f} rad behind, slip {slip:.4f}"


@pytest.mark.parametrize("fraction", [0.5, 1.5])
def test_a_driven_wheels_effort_is_what_its_motor_puts_on_it(wheel: World, fraction) -> None:
    """The joint's effort is its velocity motor's force on it (the tendon's constraint force,
    as ODE reports its motor's): against a load within the effort, the load itself (the wheel
    keeps its speed); past it, exactly the effort limit (Newton on the disc and the bound)."""
    _load(wheel, -fraction * EFFORT)
    wheel.step(300)
    efforts = []
    for _ in range(20):
        wheel.step(10)
        efforts.append(wheel.joint_states("w")[0].effort)
    expected = min(fraction, 1.0) * EFFORT
    assert efforts == pytest.approx([expected] * 20, rel=1e-6), f"efforts {efforts[:3]} N m"


def test_an_overloaded_wheel_recovers_without_a_burst(wheel: World) -> None:
    """Gazebo's joint motor, a velocity constraint bounded by FMax, comes back from a stall at
    its command: the speed after the release never passes it by more than 5 %."""
    _load(wheel, -1.5 * EFFORT)
    wheel.step(500)
    _load(wheel, 1.5 * EFFORT)
    after = _speeds(wheel, 200)
    assert after.max() < 1.05 * SPEED, f"a catch-up burst to {after.max():.2f} rad/s"


@pytest.mark.xfail(
    strict=True,
    reason="the velocity motor's friction row is soft: the held wheel creeps at 2.5e-6, 5.1e-6 "
    "and 9.1e-6 rad/s under 0.25, 0.5 and 0.9 of its effort (R·f·h, R = (1 − d)/d / I at "
    "MuJoCo's largest impedance d = 0.9999); ODE's CFM about 1e-9 holds it",
)
@pytest.mark.parametrize("fraction", [0.25, 0.5, 0.9])
def test_a_zero_velocity_command_holds_the_wheel_still_under_load(wheel: World, fraction) -> None:
    """Gazebo's FMax constraint at speed 0 (ODE, CFM about 1e-9) holds a load within its limit
    still: within 1e-6 rad and 1e-6 rad/s over 2 s, up to 0.9 of the effort."""
    wheel.command("w", "spin", mode="velocity", value=0.0)
    wheel.step(200)
    _load(wheel, -fraction * EFFORT)
    wheel.step(1000)
    start = wheel.joint_states("w")[0].position
    wheel.step(2000)
    state = wheel.joint_states("w")[0]
    assert abs(state.position - start) < 1e-6 and abs(state.velocity) < 1e-6, state


def test_a_held_wheel_slips_at_its_effort_and_stays_where_it_slipped(wheel: World) -> None:
    """Past its effort the hold slips with the effort exactly opposing the load, and once the
    load is gone the wheel stops where it is: a bounded constraint stores nothing to pay back
    (an integral servo at speed 0 sprang back by all it had slipped)."""
    wheel.command("w", "spin", mode="velocity", value=0.0)
    wheel.step(500)
    load = 1.5 * EFFORT
    _load(wheel, -load)
    speeds = _speeds(wheel, 30)
    slope = np.polyfit(np.arange(5, 30) * 0.01, speeds[5:], 1)[0]
    assert slope == pytest.approx(-(load - EFFORT) / MOMENT, rel=0.01), "I·dω/dt = load − effort"
    _load(wheel, load)
    wheel.step(500)
    slipped = wheel.joint_states("w")[0].position
    wheel.step(2000)
    assert wheel.joint_states("w")[0].position == pytest.approx(slipped, abs=1e-6), "no spring-back"


@pytest.mark.parametrize("effort", [50.0, 5.0])
def test_a_position_move_runs_at_the_velocity_limit_and_settles_without_overshoot(
    tmp_path, effort
) -> None:
    world = World()
    world.spawn(write_urdf(tmp_path, bob_arm(effort)), name="a", pose=Pose(z=1.0))
    world.command("a", "j", mode="position", value=0.0)
    world.step(1000)
    world.command("a", "j", mode="position", value=1.0)
    q, v = [], []
    for _ in range(2500):
        world.step(1)
        state = world.joint_states("a")[0]
        q.append(state.position)
        v.append(state.velocity)
    q = np.array(q)
    outside = np.flatnonzero(np.abs(q - 1.0) > 0.01)
    settle = (outside[-1] + 2) * 1e-3 if len(outside) else 0.0
    assert settle < 1.5, f"settled within 1 % after {settle:.3f} s (a 1 rad move at 1 rad/s)"
    assert q.max() - 1.0 < 0.01, f"overshoot {q.max() - 1.0:.4f} rad"
    assert max(v) <= 1.0, f"peak speed {max(v):.3f} rad/s over the 1 rad/s limit"
    assert q[-1] == pytest.approx(1.0, abs=1e-4), "holds its target under gravity"


@pytest.mark.parametrize("load", [1.0, 10.0, 100.0])
def test_a_wheel_without_an_effort_limit_holds_its_speed_under_any_load(tmp_path, load) -> None:
    """gz-sim's and gazebo_ros2_control's velocity command on a joint that states no effort
    limit is unbounded: the joint keeps its speed whatever loads it (here 1e3 to 1e5 times the
    disc's I·rad/s²), and comes back from nothing it stored when the load goes."""
    text = _wheel().replace(f'<limit effort="{EFFORT}" velocity="10"/>', "")
    world = World()
    world.spawn(write_urdf(tmp_path, text), name="w", pose=Pose(z=1.0))
    world.command("w", "spin", mode="velocity", value=SPEED)
    world.step(200)
    _load(world, -load)
    loaded = _speeds(world, 50)
    assert loaded == pytest.approx(SPEED, rel=1e-2), f"under {load} N m: {loaded.min():.4f}"
    assert world.joint_commands("w")["spin"]["effort_limit"] is None, "unbounded, as the file"
    world.push("w", torque=(0.0, 0.0, load), link="disc", duration=1e3)  # the load taken off
    released = _speeds(world, 50, every=1)
    assert released.max() <= SPEED * 1.001, f"peak {released.max():.4f} rad/s after the release"
