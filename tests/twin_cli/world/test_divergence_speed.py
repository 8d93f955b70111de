"""The divergence watchdog on finite blow-ups: a joint far past its velocity limit, a bad ctrl.

The robot is a solo12-like placeholder: a floating base with four legs of three revolute joints
each, links of 1 g and 1e-4 kg m², efforts up to 1000 N m (solo12's URDF gives its legs of
7-150 g the same) and a small velocity limit. One step of full effort from rest kicks a knee to
u·h/I, tens of thousands of rad/s, and Gazebo's velocity rule (the effort falls to 0 past the
limit) lets it coast there: finite, far past the limit, and unseen by MuJoCo's own checks.
"""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from models import _control_inertial, mjcf_ball, write_urdf
from world_helpers import spec_of

from twin_cli.world import Pose, World
from twin_cli.world.divergence import speed_bounds

EFFORT = 1000.0  # [N m] every joint's effort limit
LINK_MASS, LINK_MOMENT = 1e-3, 1e-4  # [kg], [kg m²] each leg link
KNEE = "FL_KFE"
LIMITS = (0.5, 2.0, 8.0)  # [rad/s] velocity limits tried
LEGAL_FRACTION = 0.5  # a legal kick reaches this fraction of the bound
COAST_STEPS = 100  # [steps of 1 ms] the legal kick is watched this long
LEGS = {"FL": (0.2, 0.1), "FR": (0.2, -0.1), "HL": (-0.2, 0.1), "HR": (-0.2, -0.1)}


def quadruped(velocity: float, travel: float = 10.0) -> str:
    """The placeholder's URDF: joints `<leg>_HAA/HFE/KFE` of ±`travel` [rad] (solo12's: 10)
    and `velocity` [rad/s]."""
    links = [f'<link name="base">{_control_inertial(1.0, 0.01)}</link>']
    joints = []
    for leg, (x, y) in LEGS.items():
        parent = "base"
        for k, (joint, axis) in enumerate((("HAA", "1 0 0"), ("HFE", "0 1 0"), ("KFE", "0 1 0"))):
            child = f"{leg}_{joint}_link"
            links.append(f'<link name="{child}">{_control_inertial(LINK_MASS, LINK_MOMENT)}</link>')
            origin = f"{x} {y} 0" if k == 0 else "0 0 -0.1"
            joints.append(
                f'<joint name="{leg}_{joint}" type="revolute"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="{origin}"/><axis xyz="{axis}"/>'
                f'<limit effort="{EFFORT}" lower="{-travel}" upper="{travel}" '
                f'velocity="{velocity}"/></joint>'
            )
            parent = child
    return f'<robot name="quad">{"".join(links)}{"".join(joints)}</robot>'


def _world(tmp_path, velocity: float, travel: float = 10.0) -> World:
    """A world with the placeholder `quad` at 1 m (no collision: it falls freely) and a ball."""
    world = World()
    urdf = write_urdf(tmp_path, quadruped(velocity, travel))
    world.spawn(urdf, name="quad", pose=Pose(z=1.0))
    world.spawn(spec_of(mjcf_ball()), pose=Pose(x=3.0, z=5.0))
    return world


def _kick_speed(world: World, effort: float) -> float:
    """[rad/s] the knee's speed after one step of `effort` from rest: u·h/I, I = 1/(M⁻¹)ᵢᵢ."""
    model = world.model
    dof = int(model.jnt_dofadr[model.joint(f"quad/{KNEE}").id])
    scratch = mujoco.MjData(model)
    scratch.qpos[:] = world.data.qpos
    mujoco.mj_forward(model, scratch)
    unit = np.zeros((1, model.nv))
    unit[0, dof] = 1.0
    inverse = np.zeros((1, model.nv))
    mujoco.mj_solveM(model, scratch, inverse, unit)
    return effort * model.opt.timestep * float(inverse[0, dof])


def _knee_speed(world: World) -> float:
    model = world.model
    return abs(float(world.data.qvel[model.jnt_dofadr[model.joint(f"quad/{KNEE}").id]]))


@pytest.mark.parametrize("velocity", LIMITS)
def test_knee_kicked_past_100x_its_limit_is_reset_to_spawn_and_counted(tmp_path, velocity):
    world = _world(tmp_path, velocity)
    bound = 100.0 * velocity  # the watchdog's bound: 100 × the velocity limit
    kick = _kick_speed(world, EFFORT)
    assert bound < kick < 1e6, f"premise: kick {kick:.3g} rad/s over the bound {bound} rad/s"
    ball = world.index_of("ball")
    world.command("quad", KNEE, mode="effort", value=EFFORT)  # within its limits
    world.step(1)
    spawn = world.entity("quad").spawn_state
    ix = world.index_of("quad")
    assert world.divergences == 1, f"divergences {world.divergences} (kick {kick:.3g} rad/s)"
    assert np.array_equal(world.data.qpos[ix.qpos], spawn.qpos), "quad back at its spawn qpos"
    assert np.array_equal(world.data.qvel[ix.dofs], spawn.qvel), "quad back at its spawn qvel"
    assert world.data.qvel[ball.dofs][2] < 0.0, "the ball kept falling"
    entry = world.divergence_log[0]
    assert entry.entity == "quad", f"entity {entry.entity}"
    assert f"joint '{KNEE}'" in entry.reason, f"reason names the joint: {entry.reason}"
    assert f"bound {bound:.3g} rad/s" in entry.reason, f"reason names the bound: {entry.reason}"
    speed = float(re.search(r" at (\S+) rad/s", entry.reason).group(1))
    assert speed == pytest.approx(kick, rel=0.01), f"the kick u·h/I {kick:.3g}: {entry.reason}"


@pytest.mark.parametrize("velocity", LIMITS)
def test_kick_found_at_a_batch_end_is_traced_to_its_first_step(tmp_path, velocity):
    # The speed is read at a batch's end: with ±10 rad of travel the knee, at 19 rad per step,
    # hits its stop at once and may be back under the bound by then; ±1000 rad lets it coast.
    world = _world(tmp_path, velocity, travel=1000.0)
    world.command("quad", KNEE, mode="effort", value=EFFORT)
    world.step(10)  # one batch: the replay resets the quad at each step the effort kicks it
    assert world.divergences == 10, f"divergences {world.divergences}: one per kick"
    assert world.divergence_log[0].sim_time == pytest.approx(0.001, abs=1e-12), "first step"
    assert world.data.time == pytest.approx(0.010, abs=1e-12), "the batch ran its 10 steps"
    assert all(KNEE in d.reason for d in world.divergence_log), world.divergence_log[0].reason


@pytest.mark.parametrize("velocity", LIMITS)
def test_fast_but_legal_kick_below_the_bound_is_not_reset(tmp_path, velocity):
    world = _world(tmp_path, velocity)
    bound = 100.0 * velocity  # the watchdog's bound: 100 × the velocity limit
    effort = LEGAL_FRACTION * bound / _kick_speed(world, 1.0)  # [N m] kicks to half the bound
    world.command("quad", KNEE, mode="effort", value=effort)
    peak = 0.0
    for _ in range(COAST_STEPS):
        world.step(1)
        peak = max(peak, _knee_speed(world))
    assert world.divergences == 0, f"{world.divergence_log[:1]}"
    # the kick itself, +-10 % (gravity and the base's recoil), is 50x the limit: fast, not reset
    assert peak == pytest.approx(LEGAL_FRACTION * bound, rel=0.1), f"peak {peak:.3g} rad/s"


def test_speed_bounds_are_100x_each_limit_and_1e4_on_free_and_unlimited_dofs(tmp_path):
    world = _world(tmp_path, 2.0)
    model = world.model
    names = world.entity_names()
    bounds = speed_bounds(model, {n: world.index_of(n) for n in names})
    quad, ball = world.index_of("quad"), world.index_of("ball")
    free = model.jnt_dofadr[quad.joints[0]] + np.arange(6)
    legs = np.setdiff1d(quad.dofs, free)
    assert len(legs) == 12 and np.all(bounds.bound[legs] == 200.0), "legs: 100 × 2 rad/s"
    assert np.all(bounds.bound[free] == 1e4), "quad's free joint: 1e4"
    assert np.all(bounds.bound[ball.dofs] == 1e4), "ball's free joint: 1e4"


@pytest.mark.parametrize(("dof", "unit"), [(0, "m/s"), (4, "rad/s")])
def test_free_joint_over_1e4_is_reset_and_named_with_its_unit(tmp_path, dof, unit):
    world = _world(tmp_path, 2.0)
    ball = world.index_of("ball")
    world.data.qvel[ball.dofs[dof]] = 2.0 * 1e4
    world.step(1)
    assert world.divergences == 1, "one divergence"
    assert world.divergence_log[0].entity == "ball", world.divergence_log
    reason = world.divergence_log[0].reason
    assert f"over its bound 1e+04 {unit}" in reason and "joint 'root'" in reason, reason
    assert np.all(world.data.qvel[ball.dofs] == 0.0), "ball back at rest"


def test_huge_ctrl_is_a_divergence_of_its_entity_and_reset_restores_its_ctrl(tmp_path):
    world = _world(tmp_path, 2.0)
    quad = world.index_of("quad")
    world.data.ctrl[quad.actuators[3]] = np.nan  # a bad number even after ctrlrange clamps
    world.step(5)
    assert world.divergences == 1, f"divergences {world.divergences}"
    entry = world.divergence_log[0]
    assert entry.entity == "quad" and "mjWARN_BADCTRL" in entry.reason, entry
    spawn = world.entity("quad").spawn_state
    assert np.array_equal(world.data.ctrl[quad.actuators], spawn.ctrl), "spawn ctrl restored"
