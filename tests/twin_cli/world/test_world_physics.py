"""World physics against oracles: free fall, gravity presets, standing, pushing, joint limits."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from models import mjcf_arm, mjcf_ball, mjcf_box

from twin_cli.spawn_request import SpawnRequest
from twin_cli.world import GRAVITY_PRESETS, Pose, World

DT = 0.001  # [s] the default world step


def ball_spec(radius: float = 0.1) -> mujoco.MjSpec:
    return mujoco.MjSpec.from_string(mjcf_ball(radius=radius))


@pytest.fixture(scope="module")
def humanoid_spec() -> mujoco.MjSpec:
    """The bundled humanoid converted once (spawn copies it)."""
    from converters.pipeline import convert
    from scenarios import HUMANOID

    spec, _ = convert(HUMANOID)
    return spec


def test_free_fall_follows_half_g_t_squared_until_first_contact():
    world = World()
    z0, radius, g = 2.0, 0.1, 9.81
    world.spawn(ball_spec(radius), pose=Pose(z=z0))
    worst, t = 0.0, 0.0
    while world.get_pose("ball").z - radius > 1e-3:  # until first contact
        world.step(1)
        t = world.stats().sim_time
        drop, oracle = z0 - world.get_pose("ball").z, 0.5 * g * t**2
        # MuJoCo's semi-implicit Euler drops exactly ½·g·t·dt more than ½gt²: 1% at t = 0.1 s.
        assert drop - oracle == pytest.approx(0.5 * g * t * DT, abs=1e-9), f"Euler drop at {t} s"
        if t > 0.1 + DT / 2:
            worst = max(worst, abs(drop - oracle) / oracle)
    assert t == pytest.approx(math.sqrt(2 * (z0 - radius) / g), abs=2e-3), "time of first contact"
    assert worst <= 0.01, f"free-fall drop deviates {worst:.4%} from ½gt² (limit 1%)"


def measured_acceleration(world: World, steps: int = 200) -> float:
    """Vertical acceleration [m/s²] of the entity 'ball' from its velocity after `steps`."""
    world.step(steps)
    return world.data.qvel[world.index_of("ball").dofs[2]] / (steps * DT)


def test_moon_gravity_gives_1_62_over_9_81_of_earth_acceleration():
    earth, moon = World(), World()
    for w in (earth, moon):
        w.spawn(ball_spec(), pose=Pose(z=5.0))
    moon.set_gravity(GRAVITY_PRESETS["moon"])
    ratio = measured_acceleration(moon) / measured_acceleration(earth)
    assert ratio == pytest.approx(1.62 / 9.81, rel=0.01), f"moon/earth acceleration {ratio:.5f}"
    assert moon.gravity() == (0.0, 0.0, -1.62), "gravity() reads the preset back"


def test_zero_gravity_body_at_rest_drifts_less_than_a_micrometre_in_one_second():
    world = World()
    world.set_gravity(GRAVITY_PRESETS["zero"])
    world.spawn(ball_spec(), pose=Pose(x=0.3, y=-0.2, z=1.0))
    world.step(1000)
    pose = world.get_pose("ball")
    drift = math.dist((pose.x, pose.y, pose.z), (0.3, -0.2, 1.0))
    assert drift < 1e-6, f"drift {drift:.3g} m in 1 s at zero gravity"


def test_gravity_change_takes_effect_on_the_next_step():
    world = World()
    world.spawn(ball_spec(), pose=Pose(z=5.0))
    world.step(10)
    v_before = world.data.qvel[2]
    world.set_gravity((0.0, 0.0, 0.0))
    world.step(10)
    assert world.data.qvel[2] == v_before, "vertical velocity constant once gravity is zero"


def hold_posture(world: World, name: str) -> None:
    """Position commands holding every joint at 0 (the humanoid's standing posture)."""
    for joint in world.joint_states(name):
        world.command(name, joint.name, mode="position", value=0.0)


def test_humanoid_standing_on_mu_1_feet_slips_less_than_1_cm_in_2_s(humanoid_spec):
    world = World()  # the humanoid's feet default to Gazebo mu1 = mu2 = 1.0 (≥ 0.8)
    world.spawn(SpawnRequest(humanoid_spec, on_ground=True))
    hold_posture(world, "humanoid")
    feet = {k: v for k, v in world.link_poses("humanoid").items() if "foot" in k}
    world.step(2000)
    after = world.link_poses("humanoid")
    assert len(feet) == 2, "the humanoid has two feet"
    for link, start in feet.items():
        slip = math.hypot(after[link].x - start.x, after[link].y - start.y)
        assert slip < 0.01, f"{link} slipped {slip * 1000:.2f} mm in 2 s (limit 10 mm)"
    assert world.get_pose("humanoid").z > 0.9, "the humanoid is still standing (torso z)"


def test_humanoid_pushed_toward_a_static_half_metre_box_does_not_pass_through(humanoid_spec):
    world = World()
    centre, half = (0.7, 0.0, 0.25), 0.25  # [m] a 0.5 m cube resting on the ground
    world.spawn(SpawnRequest(humanoid_spec, on_ground=True))
    world.spawn(
        mujoco.MjSpec.from_string(mjcf_box(half=(half,) * 3, free=False)),
        pose=Pose(*centre),
    )
    hold_posture(world, "humanoid")
    world.push("humanoid", force=(200.0, 0.0, 0.0), duration=0.4)  # [N] on the torso: 80 N s
    box_geoms = set(world.index_of("box").geoms.tolist())
    deepest, touched = 0.0, False
    for _ in range(150):
        world.step(10)
        contact = world.data.contact
        for (g1, g2), dist in zip(contact.geom, contact.dist, strict=True):
            if (g1 in box_geoms) != (g2 in box_geoms) and max(g1, g2) != 0:
                touched, deepest = True, max(deepest, -dist)
        for link, pose in world.link_poses("humanoid").items():
            inside = all(abs(p - c) < half for p, c in zip(pose.position(), centre, strict=True))
            assert not inside, f"link {link} origin entered the box at {pose.position()}"
    assert touched, "the push drove the humanoid into the box"
    assert deepest < 0.02, f"deepest humanoid-box penetration {deepest * 1000:.1f} mm (limit 20 mm)"


def test_joint_driven_past_its_limit_with_full_effort_stays_within_it():
    world = World()
    upper, effort = 0.5, 20.0  # [rad], [N m]
    world.spawn(mujoco.MjSpec.from_string(mjcf_arm(-0.5, upper, effort)))
    world.command("arm", "shoulder", mode="effort", value=1e6)  # clipped to the full effort
    peak = -math.inf
    for _ in range(100):
        world.step(10)
        peak = max(peak, world.joint_states("arm")[0].position)
    state = world.joint_states("arm")[0]
    assert state.effort == pytest.approx(effort), "the motor applies exactly its full effort"
    assert peak - upper < 0.02, f"transient overshoot {peak - upper:.4f} rad (limit 0.02 rad)"
    assert state.position - upper < 1e-3, f"held {state.position - upper:.5f} rad past the limit"


def test_position_command_is_clipped_to_the_joint_range_and_reached():
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(mujoco.MjSpec.from_string(mjcf_arm(-0.5, 0.5, 20.0)))
    world.command("arm", "shoulder", mode="position", value=-0.3)
    world.step(1000)
    assert world.joint_states("arm")[0].position == pytest.approx(-0.3, abs=1e-3), "target"
    world.command("arm", "shoulder", mode="position", value=-5.0)  # beyond the lower limit
    world.step(1000)
    position = world.joint_states("arm")[0].position
    assert position == pytest.approx(-0.5, abs=2e-3), f"clipped target reached: {position:.4f}"


def test_velocity_command_drives_the_joint_at_the_target_speed():
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(mujoco.MjSpec.from_string(mjcf_arm(-3.0, 3.0, 20.0)))
    world.command("arm", "shoulder", mode="velocity", value=0.5)
    world.step(300)
    speed = world.joint_states("arm")[0].velocity
    assert speed == pytest.approx(0.5, rel=0.01), f"joint speed {speed:.4f} rad/s"


def test_push_is_an_impulse_of_force_times_duration():
    world = World()
    world.set_gravity((0.0, 0.0, 0.0))
    world.spawn(ball_spec(), pose=Pose(z=1.0))  # 1 kg
    world.push("ball", force=(2.0, 0.0, 0.0), duration=0.25)
    world.step(500)
    vx = world.data.qvel[0]
    assert vx == pytest.approx(2.0 * 0.25 / 1.0, rel=1e-9), f"momentum after the push {vx}"
    assert not np.any(world.data.xfrc_applied), "the push ended after its duration"
