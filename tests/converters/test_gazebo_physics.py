"""Gazebo semantics measured on converted URDFs: min-μ incline, m·g/kp, gravity off, selfCollide."""

from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters.gazebo.contact import add_gazebo_ground
from converters.mjcf.world_options import CONE
from converters.pipeline import convert


def _load_models():
    """tests/models.py (shared URDF factories), loaded by path: tests/ stays off sys.path, where
    its converters/ and twin_cli/ folders would shadow the packages of the same names."""
    if "models" not in sys.modules:
        path = Path(__file__).resolve().parents[1] / "models.py"
        spec = importlib.util.spec_from_file_location("models", path)
        module = importlib.util.module_from_spec(spec)
        sys.modules["models"] = module
        spec.loader.exec_module(module)
    return sys.modules["models"]


models = _load_models()

G = 9.8
STEP = 0.001


def _world(tmp_path: Path, parts, gravity=(0.0, 0.0, -G)):
    """Compile a world of Gazebo's ground plus converted robots.

    Args:
        parts: (urdf_text, position [m]) pairs; entity i gets prefix "e<i>/".
        gravity: world gravity [m/s²]; tilting it by θ is the same as an incline of angle θ.
    """
    world = mujoco.MjSpec()
    world.option.timestep = STEP
    world.option.gravity = list(gravity)
    world.option.cone = CONE  # twin's worlds' friction cone
    add_gazebo_ground(world)
    for i, (text, position) in enumerate(parts):
        spec, _ = convert(models.write_urdf(tmp_path, text, f"part{i}.urdf"))
        frame = world.worldbody.add_frame(pos=list(position))
        world.attach(spec, frame=frame, prefix=f"e{i}/")
    model = world.compile()
    return model, mujoco.MjData(model)


def _slide_on_incline(tmp_path, block_mu, theta, slab_mu=None, seconds=1.0) -> float:
    """Distance [m] a 0.1 m cube slides in `seconds` on an incline of angle θ [rad]."""
    gravity = (G * math.sin(theta), 0.0, -G * math.cos(theta))
    parts = [(models.block_on_incline(block_mu), (0.0, 0.0, 0.05))]
    if slab_mu is not None:
        parts = [(models.slab(slab_mu), (0.0, 0.0, 0.0)), (models.block(block_mu), (0, 0, 0.1))]
    model, data = _world(tmp_path, parts, gravity)
    body = model.body(f"e{len(parts) - 1}/block").id
    mujoco.mj_forward(model, data)
    start = data.xpos[body, 0]
    mujoco.mj_step(model, data, nstep=round(seconds / STEP))
    return float(data.xpos[body, 0] - start)


INCLINE_CASES = [
    # (block μ, slab μ or None for Gazebo's μ=100 ground): the smaller one decides.
    pytest.param(0.3, None, id="low-mu robot on mu=100 ground"),
    pytest.param(1.0, 0.2, id="high-mu robot on low-mu slab"),
]


@pytest.mark.parametrize("block_mu,slab_mu", INCLINE_CASES)
@pytest.mark.parametrize("factor", [0.9, 1.1])
def test_block_slides_iff_tan_theta_exceeds_min_mu(tmp_path, block_mu, slab_mu, factor):
    mu = min(block_mu, slab_mu or 100.0)
    theta = math.atan(mu * factor)
    slid = _slide_on_incline(tmp_path, block_mu, theta, slab_mu)
    accel = G * math.cos(theta) * (math.tan(theta) - mu)
    if factor < 1:
        assert abs(slid) < 0.005, f"slid {slid:.4f} m in 1 s below tan θ = μ (creep ≤ 5 mm)"
    else:
        expected = 0.5 * accel
        assert slid == pytest.approx(expected, rel=0.15), f"slide {slid:.4f} m vs ½·a·t²"


@pytest.mark.parametrize("factor", [0.97, 1.03])
def test_incline_threshold_is_sharp_within_three_percent(tmp_path, factor):
    slid = _slide_on_incline(tmp_path, 0.3, math.atan(0.3 * factor))
    if factor < 1:
        assert slid < 0.005, f"slid {slid:.4f} m at 97 % of the friction angle"
    else:
        assert slid > 0.03, f"slid only {slid:.4f} m at 103 % of the friction angle"


@pytest.mark.parametrize("mu", [1.0, 100.0, 1e5])
def test_no_slip_wheels_carry_the_cart_on_gazebos_ground(tmp_path, mu):
    # Gazebo robots write μ 100 or 1e5 for "no slip"; in MuJoCo such a μ lets the wheels sink
    # to their axles (the chassis then rests on the ground), hence twin's cap.
    model, data = _world(tmp_path, [(models.wheeled_cart(mu), (0.0, 0.0, 0.21))])
    mujoco.mj_step(model, data, nstep=1500)
    clearance = data.xpos[model.body("e0/chassis").id, 2] - 0.1
    assert clearance == pytest.approx(0.1, abs=1e-4), f"chassis {clearance:.5f} m above ground"
    wheels = {model.body(f"e0/{w}").id for w in ("lf", "rf", "lb", "rb")}
    load, force = 0.0, np.zeros(6)
    for i in range(data.ncon):
        mujoco.mj_contactForce(model, data, i, force)
        bodies = {int(model.geom_bodyid[g]) for g in (data.contact[i].geom1, data.contact[i].geom2)}
        assert bodies & wheels, "only the wheels touch the ground"
        load += force[0]
    assert load == pytest.approx(42.0 * G, rel=0.01), "the wheels carry m·g"


@pytest.mark.parametrize("degrees,holds", [(60.0, True), (66.0, False)])
def test_no_slip_plate_holds_up_to_the_contact_caps_friction_angle(tmp_path, degrees, holds):
    # μ 100 becomes twin's contact cap μ 2, which holds up to atan(2) = 63.4° (a plate, which
    # does not tip over where a cube would).
    theta = math.radians(degrees)
    gravity = (G * math.sin(theta), 0.0, -G * math.cos(theta))
    plate = models.block(100.0, size=0.4, height=0.04)
    model, data = _world(tmp_path, [(plate, (0.0, 0.0, 0.02))], gravity)
    mujoco.mj_forward(model, data)
    start = data.xpos[model.body("e0/block").id, 0]
    mujoco.mj_step(model, data, nstep=1000)
    slid = float(data.xpos[model.body("e0/block").id, 0] - start)
    expected = 0.5 * G * math.cos(theta) * (math.tan(theta) - 2.0)  # ½·a·t² at t = 1 s
    assert slid < 0.005 if holds else slid == pytest.approx(expected, rel=0.15), slid


@pytest.mark.parametrize("kp", [1e4, 1e5])
def test_converted_ball_sinks_mg_over_kp(tmp_path, kp):
    mass = 2.0
    text = models.ball_on_plane(mass, kp=kp, kd=2 * math.sqrt(kp * mass))
    model, data = _world(tmp_path, [(text, (0.0, 0.0, 0.1))])
    mujoco.mj_step(model, data, nstep=1500)
    sinkage = 0.1 - data.xpos[model.body("e0/ball").id, 2]
    assert sinkage == pytest.approx(mass * G / kp, rel=0.10), f"sinkage {sinkage} m vs m·g/kp"


@pytest.mark.parametrize("tag", ["turnGravityOff", "gravity"])
def test_link_with_gravity_off_stays_put_while_sibling_falls(tmp_path, tag):
    model, data = _world(tmp_path, [(models.pendulum_pair("left", tag), (0.0, 0.0, 0.0))])
    mujoco.mj_step(model, data, nstep=500)
    left = data.qpos[model.joint("e0/left_hinge").qposadr[0]]
    right = data.qpos[model.joint("e0/right_hinge").qposadr[0]]
    assert abs(left) < 1e-6, f"gravity-off pendulum moved {left} rad"
    assert abs(right) > 0.5, f"sibling pendulum swung only {right} rad in 0.5 s"


def _dropper_rest(tmp_path, self_collide_link, model_self_collide=False) -> float:
    text = models.falling_sibling(self_collide_link, model_self_collide)
    model, data = _world(tmp_path, [(text, (0.0, 0.0, 0.5))])
    mujoco.mj_step(model, data, nstep=800)
    return float(data.qpos[model.joint("e0/drop").qposadr[0]])


@pytest.mark.parametrize("link", ["dropper", "plate"])
def test_sibling_links_collide_only_with_self_collide(tmp_path, link):
    on_plate = _dropper_rest(tmp_path, link)
    through = _dropper_rest(tmp_path, None)
    assert on_plate == pytest.approx(-0.24, abs=0.005), f"cube rest {on_plate} m, not on plate"
    assert through < -0.5, f"cube at {through} m: without selfCollide it must fall through"


def test_model_self_collide_enables_all_pairs(tmp_path):
    rest = _dropper_rest(tmp_path, None, model_self_collide=True)
    assert rest == pytest.approx(-0.24, abs=0.005), f"cube rest {rest} m with <self_collide>"


def test_robot_still_collides_with_ground_without_self_collide(tmp_path):
    model, data = _world(tmp_path, [(models.block(0.5), (0.0, 0.0, 0.3))])
    mujoco.mj_step(model, data, nstep=600)
    z = data.xpos[model.body("e0/block").id, 2]
    assert z == pytest.approx(0.05, abs=0.002), f"block z {z} m: must rest on the ground"
    assert np.all(np.isfinite(data.qpos)), "state finite"
