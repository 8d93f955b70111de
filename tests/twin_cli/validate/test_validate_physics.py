"""Physics checks on the bundled humanoid and on broken robots, against physical oracles."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import validate_robots as robots

import scenarios
from twin_cli.validate.checks.base import Status
from twin_cli.validate.robot import load_robot
from twin_cli.validate.runner import run_check
from twin_cli.validate.scenario import resolve

G = 9.81


@pytest.fixture(scope="module")
def humanoid():
    return load_robot(scenarios.HUMANOID)


PASSING = [
    "free_fall",
    "zero_gravity",
    "moon_gravity",
    "ground_contact",
    "friction_standing",
    "friction_incline",
    "collision",
    "joint_limits",
    "inertia",
    "stability",
    "realtime",
]


@pytest.mark.parametrize("scenario", PASSING)
def test_bundled_humanoid_passes(humanoid, scenario):
    outcome = run_check(humanoid, resolve(scenario), debug=True)
    assert outcome.status is Status.PASS, f"{scenario}: {outcome.measured}; {outcome.hints}"


def test_free_fall_follows_half_g_t_squared_at_every_sample(humanoid):
    outcome = run_check(humanoid, resolve("free_fall"), debug=True)
    (series,) = outcome.series
    t = np.array(series.t)
    drop = np.array(series.values["measured drop"])
    late = t > 0.1  # relative error of tiny early drops is dominated by the 1 ms step
    np.testing.assert_allclose(drop[late], 0.5 * G * t[late] ** 2, rtol=0.01, err_msg="COM drop")


def test_moon_ratio_is_measured_not_assumed(humanoid):
    outcome = run_check(humanoid, resolve("moon_gravity"), debug=True)
    assert math.isclose(outcome.value, 1.62 / 9.81, rel_tol=0.01), "a_moon / g_earth"


def test_soft_contact_fails_ground_contact_with_kp_hint(tmp_path):
    robot = load_robot(robots.write(tmp_path, robots.crate(kp=1000.0)))
    outcome = run_check(robot, resolve("ground_contact"), debug=True)
    assert outcome.status is Status.FAIL
    hint = outcome.hints[0]
    assert hint.startswith("crate sinks") and "kp 1e+03 N/m is too soft for the load" in hint, hint
    # The kp asked for holds the measured load of a corner (kp·depth) within the limit.
    needed = float(re.search(r"to ≥ ([0-9.e+]+) N/m", hint).group(1))
    limit = float(re.search(r"\(limit ([0-9.]+) mm\)", hint).group(1)) * 1e-3
    assert needed >= 1000.0 * outcome.value / limit, hint
    # Oracle: a box rests on 4 contact points, each a kp spring as in Gazebo: M·g / (4 kp).
    expected = 5.5 * G / (4 * 1000.0)
    assert math.isclose(outcome.value, expected, rel_tol=0.15), "crate sinkage [m]"


def test_unenforced_limit_fails_joint_limits_naming_the_joint(tmp_path):
    robot = load_robot(robots.unenforced_limit_mjcf(tmp_path))
    outcome = run_check(robot, resolve("joint_limits"), debug=True)
    assert outcome.status is Status.FAIL
    assert "joint 'elbow'" in outcome.hints[0] and "not enforced" in outcome.hints[0]


def test_intact_crate_passes_contact_and_limits(tmp_path):
    robot = load_robot(robots.write(tmp_path, robots.crate()))
    for name in ("ground_contact", "collision", "stability"):
        outcome = run_check(robot, resolve(name), debug=True)
        assert outcome.status is Status.PASS, f"{name}: {outcome.hints}"


def test_friction_incline_probe_slides_iff_tan_theta_exceeds_mu(humanoid):
    """A foot-surface probe on slopes at tan θ = 0.8 μ and 1.25 μ (μ = min(1, 100) = 1):
    Coulomb says it sticks on the first and slides ½·g·(sin θ − μ cos θ)·t² on the second."""
    from twin_cli.validate.checks.physics_friction import foot_geoms, probe_spec, slide_on_slope
    from twin_cli.validate.checks.sim import ScenarioRun

    scenario = resolve("friction_incline")
    outcome = run_check(humanoid, scenario, debug=True)
    assert "μ = 1" in outcome.measured, "humanoid feet μ=1 against the ground's 100: min is 1"
    spec = probe_spec(humanoid.model, foot_geoms(ScenarioRun(humanoid, scenario))[0])
    t = scenario.duration
    stuck = slide_on_slope(humanoid, spec, scenario, math.atan(0.8))
    assert stuck < 0.01, f"probe crept {stuck:.4f} m at tan θ = 0.8 μ (soft-friction creep < 1 cm)"
    theta = math.atan(1.25)
    coulomb = 0.5 * G * (math.sin(theta) - math.cos(theta)) * t * t
    slid = slide_on_slope(humanoid, spec, scenario, theta)
    assert math.isclose(slid, coulomb, rel_tol=0.15), f"slid {slid:.4f} m, Coulomb {coulomb:.4f} m"


def test_robot_fixed_to_the_world_skips_fall_and_contact_checks(tmp_path):
    robot = load_robot(robots.write(tmp_path, robots.crate(fixed=True)))
    for name in ("free_fall", "moon_gravity", "ground_contact", "collision", "friction_standing"):
        outcome = run_check(robot, resolve(name), debug=True)
        assert outcome.status is Status.NOT_APPLICABLE, f"{name}: {outcome.measured}"
        assert "fixed to the world" in outcome.details[0], outcome.details
    assert run_check(robot, resolve("joint_limits"), debug=True).status is Status.PASS
