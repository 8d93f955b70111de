"""Gazebo contact rules (`converters.gazebo.contact`) proved on hand-built MjSpecs by MuJoCo."""

from __future__ import annotations

import itertools
import math

import mujoco
import numpy as np
import pytest

from converters.gazebo.contact import (
    DAMPING_RATIO,
    DEFAULT_LIMIT_ERP,
    GROUND_MU,
    HARD_IMPEDANCE,
    LIMIT_SOLIMP,
    PRIORITY_PER_DECADE,
    add_gazebo_ground,
    contact_softness,
    friction_priority,
    limit_solref,
    max_contact_stiffness,
)
from converters.mjcf.world_options import CONE

G = 9.8
STEP = 0.001


def steady_limit_violation(a0: float) -> float:
    """MuJoCo's steady limit violation [rad] for Gazebo's default limit (erp 0.2, 1 ms step).

    At rest 0 = (1 − d)·a0 − d·k·r, and MuJoCo's stiffness at d = dmax is k = 1/(d·τ²·ζ²);
    with τ = 2h and ζ = 1/(2√erp) that gives r = (1 − d)·a0·h²/erp. d = 0.9999 is the impedance
    twin's limits use (MuJoCo's maximum).
    """
    d, erp = 0.9999, 0.2
    return (1.0 - d) * a0 * STEP**2 / erp


def _world(gravity: tuple[float, float, float] = (0.0, 0.0, -G)) -> mujoco.MjSpec:
    spec = mujoco.MjSpec()
    spec.option.timestep = STEP
    spec.option.gravity = list(gravity)
    spec.option.cone = CONE  # twin's worlds' friction cone
    add_gazebo_ground(spec)
    return spec


def _free_geom(spec: mujoco.MjSpec, geom_type, size, z: float, mass: float, mu: float, soft=None):
    body = spec.worldbody.add_body(name=f"b{len(spec.bodies)}", pos=[0.0, 0.0, z])
    body.add_freejoint()
    geom = body.add_geom(type=geom_type, size=size, mass=mass)
    geom.friction = [mu, 0.005, 0.0001]
    geom.priority = friction_priority(mu)
    if soft is not None:
        geom.solref = list(soft.solref)
        geom.solimp = list(soft.solimp)
    return body


def test_friction_priority_strictly_decreases_with_mu():
    mus = np.logspace(-4, 6, 400)
    priorities = [friction_priority(float(mu)) for mu in mus]
    assert all(a > b for a, b in itertools.pairwise(priorities)), "priority not decreasing in μ"
    assert all(p >= 0 for p in priorities), "priority must be non-negative"
    step = 10 ** (1 / PRIORITY_PER_DECADE) - 1
    assert friction_priority(1.0) != friction_priority(1.0 * (1 + 2 * step)), "quantisation"


@pytest.mark.parametrize("mu_a,mu_b", [(0.01, 100.0), (0.3, 1.0), (5.0, 0.7), (1e5, 100.0)])
def test_contact_friction_is_min_of_both_geoms(mu_a, mu_b):
    """Two overlapping spheres of any μ pair get friction min(μa, μb) in MuJoCo's contact."""
    spec = _world()
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_SPHERE, [0.1, 0, 0], 1.0, 1.0, mu_a)
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_SPHERE, [0.1, 0, 0], 1.15, 1.0, mu_b)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    pair = [c for c in data.contact[: data.ncon] if 0 not in (c.geom1, c.geom2)]
    assert len(pair) == 1, f"expected one sphere-sphere contact, got {len(pair)}"
    assert pair[0].friction[0] == pytest.approx(min(mu_a, mu_b), rel=1e-12), "contact μ"


@pytest.mark.parametrize("mu", [0.05, 1.0, 99.0, 150.0])
def test_robot_on_gazebo_ground_gets_min_mu(mu):
    spec = _world()
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_SPHERE, [0.1, 0, 0], 0.099, 1.0, mu)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.ncon == 1, "sphere must touch the ground"
    assert data.contact[0].friction[0] == pytest.approx(min(mu, GROUND_MU)), "ground contact μ"


def test_gazebo_ground_is_named_plane_with_mu_100():
    model = _world().compile()
    ground = model.geom("ground")
    assert ground.type[0] == mujoco.mjtGeom.mjGEOM_PLANE, "ground type"
    assert ground.friction[0] == pytest.approx(100.0), "ground μ"
    assert ground.priority[0] == friction_priority(100.0), "ground priority"


def _settle_ball(kp: float, kd: float, mass: float, seconds: float = 1.0, mu: float = 1.0):
    soft = contact_softness(kp, kd, mass)
    spec = _world()
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_SPHERE, [0.1, 0, 0], 0.1, mass, mu, soft)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=int(seconds / STEP))
    return 0.1 - data.qpos[2], soft, model, data


@pytest.mark.parametrize("kp,mass", [(1e4, 1.0), (1e5, 1.0), (2e5, 5.0)])
def test_resting_ball_sinks_mg_over_kp(kp, mass):
    sinkage, _, _, _ = _settle_ball(kp, 2 * math.sqrt(kp * mass), mass)
    expected = mass * G / kp
    assert sinkage == pytest.approx(expected, rel=0.02), f"sinkage {sinkage} m vs m·g/kp"


@pytest.mark.parametrize("mu", [0.05, 0.2, 0.7, 1.3, 2.0])
@pytest.mark.parametrize("kp", [3e3, 1e6])
def test_resting_ball_sinks_mg_over_kp_at_every_mu_and_the_report_says_so(kp, mu):
    """On the elliptic cone the normal row keeps its own regulariser whatever μ is: the ball
    rests at m·g/kp, and the settings report that sinkage."""
    sinkage, soft, _, _ = _settle_ball(kp, 1.0, 1.5, seconds=3.0, mu=mu)
    assert sinkage == pytest.approx(1.5 * G / kp, rel=0.02), f"μ {mu}: {sinkage} m"
    assert soft.sinkage == pytest.approx(sinkage, rel=0.02), "reported sinkage"


def test_resting_box_sinks_a_quarter_on_four_contacts():
    kp, mass = 1e5, 1.0
    soft = contact_softness(kp, 2 * math.sqrt(kp * mass), mass)
    spec = _world()
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_BOX, [0.05, 0.05, 0.05], 0.05, mass, 1.0, soft)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=1000)
    assert data.ncon == 4, "box on plane: four contact points"
    sinkage = 0.05 - data.qpos[2]
    assert sinkage == pytest.approx(mass * G / kp / 4, rel=0.02), "box sinkage vs m·g/(4·kp)"


@pytest.mark.parametrize(("kp", "kd"), [(3e4, 1.0), (1e6, 1.0), (None, None)])
def test_a_dropped_ball_lands_without_a_bounce(kp, kd):
    """Gazebo pushes a penetration out at most at the surface's max_vel (0.01 m/s by default),
    so a drop does not bounce: the rebound may not pass max_vel²/(2g) (5 µm) above rest."""
    soft = contact_softness(kp, kd, 1.0)
    spec = _world()
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_SPHERE, [0.1, 0, 0], 0.3, 1.0, 1.0, soft)
    model = spec.compile()
    data = mujoco.MjData(model)
    heights, rising = [], False
    for _ in range(1500):
        mujoco.mj_step(model, data)
        rising = rising or (data.ncon > 0 and data.qvel[2] >= 0.0)  # stopped by the ground
        if rising:
            heights.append(data.qpos[2])
    rest = 0.1 - soft.sinkage
    assert max(heights) - rest <= 0.01**2 / (2 * G), f"bounced {max(heights) - rest:.2e} m"
    assert heights[-1] == pytest.approx(rest, abs=2e-6), "settles at its sinkage"


def test_a_resting_box_presses_steadily_on_its_four_corners():
    """SDF's rigid default under a 3.85 kg box: the total normal force stays at m·g within 5 %
    from step to step (it swung between 0 and 2·m·g with MuJoCo's spring at the step's bound)."""
    mass = 3.85
    spec = _world()
    soft = contact_softness(None, None, mass)
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_BOX, [0.1, 0.1, 0.1], 0.1, mass, 1.0, soft)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=1000)
    forces = []
    for _ in range(1000):
        mujoco.mj_step(model, data)
        wrench = np.zeros(6)
        total = 0.0
        for c in range(data.ncon):
            mujoco.mj_contactForce(model, data, c, wrench)
            total += wrench[0]
        forces.append(total)
    forces = np.array(forces)
    assert np.abs(forces - mass * G).max() < 0.05 * mass * G, (forces.min(), forces.max())


def test_a_box_on_a_slope_below_its_friction_angle_does_not_creep():
    """tan 34° = 0.68 < μ = 1: it holds, as Gazebo's velocity-level friction does (MuJoCo's soft
    friction creeps as (1 - d)/B: 22.6 mm in 10 s at the former d 0.95, ζ 0.5)."""
    theta = math.radians(34.0)
    spec = _world((G * math.sin(theta), 0.0, -G * math.cos(theta)))
    soft = contact_softness(None, None, 1.0)
    _free_geom(spec, mujoco.mjtGeom.mjGEOM_BOX, [0.05, 0.05, 0.05], 0.05, 1.0, 1.0, soft)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data, nstep=1000)
    start = data.qpos[0]
    mujoco.mj_step(model, data, nstep=10000)
    assert abs(data.qpos[0] - start) < 1e-4, f"crept {data.qpos[0] - start:.2e} m in 10 s"


def test_a_frictionless_surface_gets_a_frictionless_contact(tmp_path):
    """Gazebo's μ 0 (a caster): condim 1 in MuJoCo, whose friction pyramid of zero width left a
    two-wheeled base leaping off the ground."""
    from converters import convert

    urdf = tmp_path / "caster.urdf"
    urdf.write_text(
        '<robot name="c"><link name="ball"><inertial><mass value="1"/><inertia ixx="1e-3" '
        'iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
        '<sphere radius="0.05"/></geometry></collision></link><gazebo reference="ball">'
        "<mu1>0</mu1><mu2>0</mu2></gazebo></robot>"
    )
    spec, _ = convert(urdf)
    (geom,) = [g for g in spec.geoms if g.contype]
    assert geom.condim == 1 and geom.friction[0] == 0.0


def test_stiffer_than_timestep_is_clamped_and_sinks_as_reported():
    kp, mass = 1e8, 1.0
    sinkage, soft, _, _ = _settle_ball(kp, 2 * math.sqrt(kp * mass), mass)
    assert soft.clamped, "kp/m = 1e8 /s² must be clamped at a 1 ms step"
    assert -soft.solref[0] == pytest.approx(max_contact_stiffness(STEP)), "clamped stiffness"
    assert sinkage == pytest.approx(soft.sinkage, rel=0.02), "sinkage vs reported figure"
    assert np.isfinite(sinkage) and sinkage > 0, "clamped contact must stay stable"


def test_low_gazebo_damping_is_raised_and_says_so():
    soft = contact_softness(1e6, 1.0, 1.0)
    assert soft.damping_ratio_gazebo == pytest.approx(1.0 / (2 * 1e3)), "Gazebo ζ figure"
    assert soft.damping_ratio == pytest.approx(DAMPING_RATIO), "overdamped at the cap"
    assert soft.solimp[0] <= HARD_IMPEDANCE


def test_limit_solref_follows_stop_erp():
    assert limit_solref(0.2) == pytest.approx((0.002, 1.0 / (2 * math.sqrt(0.2)))), "τ=2h, ζ"
    assert limit_solref(1.0) == pytest.approx((0.002, 0.5)), "erp 1: dead-beat"
    assert limit_solref(None) == limit_solref(DEFAULT_LIMIT_ERP), "SDF default erp 0.2"


def _hinge(inertia: float, erp: float | None, lower: float = -1.0, upper: float = 1.0):
    """A hinge (axis z, range [lower, upper] rad) on a body of `inertia` [kg m²], no gravity,
    with the converter's limit settings for `erp`; returns (model, data)."""
    spec = _world(gravity=(0.0, 0.0, 0.0))
    spec.compiler.degree = False
    body = spec.worldbody.add_body(name="link", mass=1.0, inertia=[inertia] * 3)
    body.explicitinertial = True
    joint = body.add_joint(name="hinge", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    joint.range = [lower, upper]
    joint.solref_limit = list(limit_solref(erp))
    joint.solimp_limit = list(LIMIT_SOLIMP)
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.01], contype=0, conaffinity=0)
    model = spec.compile()
    return model, mujoco.MjData(model)


@pytest.mark.parametrize("erp", [0.2, 0.5, 0.9])
@pytest.mark.parametrize("start", [0.001, 0.01, 0.1])
def test_limit_sets_the_velocity_ode_sets_from_a_violation(erp, start):
    """ODE's cfm-0 limit row sets v' = −erp·r/h in one step (±0.1 %), from rest at r past the
    stop; a limit can only push, so afterwards the joint leaves at that speed, as in ODE."""
    model, data = _hinge(0.01, erp)
    data.qpos[0] = 1.0 + start
    mujoco.mj_step(model, data)
    assert data.qvel[0] == pytest.approx(-erp * start / STEP, rel=1e-3), "v' = −erp·r/h"


def test_pressed_limit_violation_decays_by_one_minus_erp_per_step():
    """Held into the stop by 1000 N m on 0.01 kg m², a 10 mrad violation shrinks by (1 − erp)
    per step (±1 %) towards the steady residue, as ODE's row does."""
    erp = DEFAULT_LIMIT_ERP
    model, data = _hinge(0.01, erp)
    data.qpos[0] = 1.01
    data.qfrc_applied[0] = 1000.0
    residue = steady_limit_violation(1000.0 / 0.01)
    excess = []
    for _ in range(6):
        mujoco.mj_step(model, data)
        excess.append(data.qpos[0] - 1.0 - residue)
    ratios = np.array(excess[1:]) / np.array(excess[:-1])
    assert ratios == pytest.approx(1.0 - erp, rel=0.01), f"per-step ratios {ratios}"


def test_limit_impact_is_stopped_in_one_step_without_elastic_rebound():
    """A joint hitting its stop at 50 rad/s overshoots by at most one step of travel and leaves
    at erp·overshoot/h (ODE's error correction, 10 rad/s here), not at 50 rad/s."""
    model, data = _hinge(0.01, None)
    data.qpos[0], data.qvel[0] = 0.9, 50.0
    for _ in range(100):
        if data.qpos[0] > 1.0:
            break
        mujoco.mj_step(model, data)
    overshoot = data.qpos[0] - 1.0
    assert 0.0 < overshoot <= 50.0 * STEP + 1e-9, f"overshoot {overshoot:.4f} rad"
    mujoco.mj_step(model, data)
    expected = -DEFAULT_LIMIT_ERP * overshoot / STEP
    assert data.qvel[0] == pytest.approx(expected, rel=1e-3), "leaves at erp·r/h"


@pytest.mark.parametrize("torque, inertia", [(1000.0, 1e-4), (28.0, 1e-3), (80.0, 0.05)])
def test_limit_gives_way_by_the_predicted_residue_under_full_effort(torque, inertia):
    """Held against the stop by τ on I, the steady violation is (1 − d)·a0·h²/erp (±2 %) and
    stays within 0.05 rad for every corpus effort-to-inertia ratio up to 1e7 rad/s²."""
    model, data = _hinge(inertia, None)
    data.qfrc_applied[0] = torque
    for _ in range(3000):
        mujoco.mj_step(model, data)
    measured = data.qpos[0] - 1.0
    predicted = steady_limit_violation(torque / inertia)
    assert measured == pytest.approx(predicted, rel=0.02), f"violation {measured:.3e} rad"
    assert measured < 0.05, "within joint_limits' 0.05 rad"
