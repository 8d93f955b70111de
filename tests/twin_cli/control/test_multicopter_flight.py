"""A quadrotor with gz-sim's MulticopterMotorModel flies in twin: hover, climb, yaw, motor lag.

Oracle: rigid-body formulas with the plugin's own definitions, independent of twin's code:
thrust T = motorConstant·ω² per rotor, yaw moment −dir·momentConstant·T (dir +1 ccw, −1 cw),
hover speed ω_h = √(m·g / (4·motorConstant)), climb acceleration (ΣT − m·g)/m, yaw acceleration
Στ / I_zz of the whole vehicle (body and rotors about the vehicle's z axis), damped by the rotor
drag −|ω|·rotorDragCoefficient·v⊥.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from twin_cli.errors import InvalidRequestError
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import Pose, World

MOTOR_CONSTANT = 8.54858e-06  # [N s²/rad²], PX4's x500
MOMENT_CONSTANT = 0.016  # [m]
ROTOR_DRAG = 8.06428e-05  # [N s²/rad/m]
ARM = 0.25  # [m] centre to rotor
TAU_UP, TAU_DOWN = 0.0125, 0.025  # [s]
MAX_SPEED = 1000.0  # [rad/s]
START = 1.0  # [m] height the quadrotor flies from
ROTORS = ((1, -1, "ccw"), (-1, 1, "ccw"), (1, 1, "cw"), (-1, -1, "cw"))  # x, y signs; direction


def _rotor(i: int, x: float, y: float, direction: str) -> tuple[str, str, str]:
    link = f"""<link name="rotor_{i}"><pose>{x} {y} 0.06 0 0 0</pose><inertial><mass>0.016</mass>
<inertia><ixx>1e-6</ixx><iyy>2.7e-4</iyy><izz>2.7e-4</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz>
</inertia></inertial></link>"""
    joint = f"""<joint name="rotor_{i}_joint" type="revolute"><parent>base_link</parent>
<child>rotor_{i}</child><axis><xyz>0 0 1</xyz></axis></joint>"""
    plugin = f"""<plugin filename="gz-sim-multicopter-motor-model-system"
name="gz::sim::systems::MulticopterMotorModel"><jointName>rotor_{i}_joint</jointName>
<linkName>rotor_{i}</linkName><turningDirection>{direction}</turningDirection>
<timeConstantUp>{TAU_UP}</timeConstantUp><timeConstantDown>{TAU_DOWN}</timeConstantDown>
<maxRotVelocity>{MAX_SPEED}</maxRotVelocity><motorConstant>{MOTOR_CONSTANT}</motorConstant>
<momentConstant>{MOMENT_CONSTANT}</momentConstant><motorNumber>{i}</motorNumber>
<rotorDragCoefficient>{ROTOR_DRAG}</rotorDragCoefficient>
<rollingMomentCoefficient>1e-06</rollingMomentCoefficient>
<rotorVelocitySlowdownSim>10</rotorVelocitySlowdownSim><motorType>velocity</motorType></plugin>"""
    return link, joint, plugin


def quadrotor() -> str:
    """An x500-like quadrotor: 2 kg, rotors 0.25 m from the centre, alternating directions."""
    a = ARM / math.sqrt(2.0)
    parts = [_rotor(i, sx * a, sy * a, d) for i, (sx, sy, d) in enumerate(ROTORS)]
    body = """<link name="base_link"><inertial><mass>1.936</mass><inertia><ixx>0.0217</ixx>
<iyy>0.0217</iyy><izz>0.04</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
<collision name="c"><geometry><box><size>0.35 0.35 0.1</size></box></geometry></collision>
</link>"""
    rest = "".join("".join(p[k] for p in parts) for k in range(3))
    return f'<sdf version="1.9"><model name="quad">{body}{rest}</model></sdf>'


@pytest.fixture
def world() -> World:
    w = World()
    w.spawn(SpawnRequest(xml=quadrotor()), name="quad", pose=Pose(z=START))
    return w


def _mass_gravity(world: World) -> tuple[float, float]:
    m = world.model
    mass = sum(float(m.body_mass[b]) for b in range(m.nbody) if m.body(b).name.startswith("quad/"))
    return mass, -float(m.opt.gravity[2])


def _speeds(world: World, omegas: list[float]) -> None:
    world.command_joints(
        "quad", {f"rotor_{i}_joint": w for i, w in enumerate(omegas)}, mode="velocity"
    )


def _spun_up(world: World, omegas: list[float]) -> None:
    """Rotors at `omegas` for 0.3 s (24 lags), then the vehicle back at START at rest."""
    _speeds(world, omegas)
    world.step(round(0.3 / world.model.opt.timestep))
    world.set_pose("quad", Pose(z=START))


def _base_dofs(world: World) -> np.ndarray:
    m = world.model
    free = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "quad/base_link")
    return world.data.qvel[m.body_dofadr[free] : m.body_dofadr[free] + 6]


def test_hover_speed_holds_height_for_10_s(world: World) -> None:
    mass, g = _mass_gravity(world)
    hover = math.sqrt(mass * g / (4 * MOTOR_CONSTANT))
    _spun_up(world, [hover] * 4)
    z0, drift = world.get_pose("quad").z, 0.0
    for _ in range(100):  # 10 s of sim time, sampled every 0.1 s
        world.step(round(0.1 / world.model.opt.timestep))
        drift = max(drift, abs(world.get_pose("quad").z - z0))
    assert drift < 0.01


def test_spin_up_lag_sinks_at_g_times_time_constant(world: World) -> None:
    """From rest, filtered thrust lacks m·g·τ of impulse: the vehicle sinks at g·τ_up (within
    one step of delay: MuJoCo integrates the activation after using it)."""
    mass, g = _mass_gravity(world)
    _speeds(world, [math.sqrt(mass * g / (4 * MOTOR_CONSTANT))] * 4)
    h = world.model.opt.timestep
    world.step(round(0.3 / h))
    sink = -float(_base_dofs(world)[2])
    assert g * TAU_UP * 0.99 < sink < g * (TAU_UP + h) * 1.01


def test_ten_percent_over_hover_climbs_at_thrust_minus_weight(world: World) -> None:
    mass, g = _mass_gravity(world)
    omega = 1.1 * math.sqrt(mass * g / (4 * MOTOR_CONSTANT))
    _spun_up(world, [omega] * 4)
    h = world.model.opt.timestep
    world.step(round(0.2 / h))
    v0, t0 = float(_base_dofs(world)[2]), float(world.data.time)
    world.step(round(1.0 / h))
    measured = (float(_base_dofs(world)[2]) - v0) / (float(world.data.time) - t0)
    expected = (4 * MOTOR_CONSTANT * omega**2 - mass * g) / mass
    assert measured == pytest.approx(expected, rel=0.02)


def test_differential_speeds_yaw_as_turning_direction_says(world: World) -> None:
    """ccw rotors faster: each pushes the body by −momentConstant·T about z, so it yaws cw.

    Rotor drag −|ω|·C·v⊥ on rotors moving at r·ψ' damps the yaw by c = Σ|ω|·C·r², so the yaw
    rate follows ψ'(t) = τ/c + (ψ'₀ − τ/c)·exp(−c·t/I)."""
    mass, g = _mass_gravity(world)
    hover = math.sqrt(mass * g / (4 * MOTOR_CONSTANT))
    fast, slow = 1.05 * hover, 0.95 * hover
    _spun_up(world, [fast, fast, slow, slow])
    h = world.model.opt.timestep
    world.step(round(0.1 / h))
    r0, t0 = float(_base_dofs(world)[5]), float(world.data.time)
    world.step(round(0.5 / h))
    torque = -2 * MOMENT_CONSTANT * MOTOR_CONSTANT * (fast**2 - slow**2)
    damping = 4 * hover * ROTOR_DRAG * ARM**2
    decay = math.exp(-damping * (float(world.data.time) - t0) / _yaw_inertia(world))
    expected = torque / damping + (r0 - torque / damping) * decay
    measured = float(_base_dofs(world)[5])
    assert r0 < 0 and measured < r0
    assert measured == pytest.approx(expected, rel=0.02)


def _yaw_inertia(world: World) -> float:
    """I_zz of body and rotors about the vehicle's z (principal axes aligned, as written)."""
    m, total = world.model, 0.0
    for b in range(m.nbody):
        if m.body(b).name.startswith("quad/"):
            x, y = world.data.xipos[b][:2] - world.data.xipos[m.body("quad/base_link").id][:2]
            total += float(m.body_inertia[b][2]) + float(m.body_mass[b]) * (x * x + y * y)
    return total


def test_rotor_speeds_clamp_and_modes(world: World) -> None:
    """Speeds above maxRotVelocity are refused by `command_joints` and clamped by `command`;
    a rotor offers only the velocity mode; thrust ctrl is ω|ω|."""
    with pytest.raises(InvalidRequestError):
        world.command_joints("quad", {"rotor_0_joint": MAX_SPEED * 1.1}, mode="velocity")
    with pytest.raises(InvalidRequestError):
        world.command_joints("quad", {"rotor_0_joint": 500.0}, mode="position")
    world.command("quad", "rotor_0_joint", mode="velocity", value=MAX_SPEED * 2)
    thrust = world.model.actuator("quad/rotor_0_joint:thrust").id
    assert world.data.ctrl[thrust] == pytest.approx(MAX_SPEED**2)
    spin = world.model.actuator("quad/rotor_0_joint").id
    assert world.model.actuator_dynprm[spin, 0] == pytest.approx(TAU_UP)
    world.command("quad", "rotor_0_joint", mode="velocity", value=100.0)
    assert world.model.actuator_dynprm[thrust, 0] == pytest.approx(TAU_UP)  # act still 0
    world.step(200)
    world.command("quad", "rotor_0_joint", mode="velocity", value=50.0)
    assert world.model.actuator_dynprm[thrust, 0] == pytest.approx(TAU_DOWN)
    assert world.data.ctrl[thrust] == pytest.approx(2500.0)


def test_a_recompile_keeps_rotor_thrust_and_lag(world: World) -> None:
    """Spawning another entity recompiles the world; the rotor commands are written again."""
    mass, g = _mass_gravity(world)
    hover = math.sqrt(mass * g / (4 * MOTOR_CONSTANT))
    _spun_up(world, [hover] * 4)
    box = '<sdf version="1.9"><model name="box"><link name="l"/></model></sdf>'
    world.spawn(SpawnRequest(xml=box), name="box", pose=Pose(x=3.0))
    world.set_pose("quad", Pose(z=START))
    world.step(round(1.0 / world.model.opt.timestep))
    thrust = world.model.actuator("quad/rotor_0_joint:thrust").id
    assert world.data.ctrl[thrust] == pytest.approx(hover**2)
    assert world.get_pose("quad").z == pytest.approx(START, abs=0.01)
