"""Model checks: each deliberately broken robot fails the right check with a hint naming the link.

Also the oracle behind the plausibility check (solid volumes and inertias of MuJoCo geoms) and
the corpus robots, which pass or fail for the reasons their upstream files really have.
"""

from __future__ import annotations

import math

import pytest
import validate_robots as robots
from corpus_registry import CORPUS, corpus_ids

from twin_cli.validate.checks import MODEL_CHECKS
from twin_cli.validate.checks.base import Status
from twin_cli.validate.robot import load_robot, robot_from_conversion
from twin_cli.validate.runner import _model_scenario, run_check


def model_results(path, **kwargs) -> dict:
    robot = load_robot(path, **kwargs)
    names = (
        "inertial",
        "inertia_tensor",
        "inertia_plausible",
        "mesh_complexity",
        "initial_overlap",
        "joint_definitions",
    )
    return {n: run_check(robot, _model_scenario(n), debug=True) for n in names}


def failing(results: dict) -> set[str]:
    return {name for name, r in results.items() if r.status is Status.FAIL}


def test_intact_crate_passes_every_model_check(tmp_path):
    results = model_results(robots.write(tmp_path, robots.crate()))
    assert failing(results) == set(), {n: r.hints for n, r in results.items()}
    ratio = results["inertia_plausible"].value
    assert math.isclose(ratio, 5.0 / (0.3 * 0.3 * 0.1 * 1000), rel_tol=1e-6), (
        "lowest ratio should be the crate's density / 1000 kg/m³ (its inertia is the solid's)"
    )


def test_link_without_inertial_fails_inertial_and_names_it(tmp_path):
    path = robots.write(tmp_path, robots.crate(arm_inertial=False))
    results = model_results(path)
    assert failing(results) == {"inertial"}
    hint = results["inertial"].hints[0]
    assert "'arm'" in hint and "<inertial>" in hint and "<mass>" in hint, hint


def test_accepting_inertia_repairs_turns_the_failure_into_a_warning(tmp_path):
    path = robots.write(tmp_path, robots.crate(arm_inertial=False))
    assert model_results(path, repair_inertia=True)["inertial"].status is Status.WARN


def test_tiny_inertia_on_heavy_link_fails_plausibility(tmp_path):
    path = robots.write(tmp_path, robots.crate(arm_mass=5.0, arm_inertia=1e-9))
    results = model_results(path)
    assert failing(results) == {"inertia_plausible"}
    hint = results["inertia_plausible"].hints[0]
    assert "'arm'" in hint and "too small" in hint and "5 kg" in hint, hint


def test_overlap_between_colliding_links_fails_pair_by_pair(tmp_path):
    path = robots.write(tmp_path, robots.crate(flap_overlaps_arm=True, arm_self_collide=True))
    results = model_results(path)
    assert failing(results) == {"initial_overlap"}
    hint = results["initial_overlap"].hints[0]
    assert "'arm' and 'flap'" in hint and "20 mm" in hint, hint


def test_overlap_without_self_collide_is_only_a_warning(tmp_path):
    results = model_results(robots.write(tmp_path, robots.crate(flap_overlaps_arm=True)))
    overlap = results["initial_overlap"]
    assert overlap.status is Status.WARN and "selfCollide off" in overlap.details[0]


def test_20000_triangle_collision_mesh_fails_unless_simplified(tmp_path):
    stl = robots.dense_sphere_stl(tmp_path, subdivisions=5)
    path = robots.write(tmp_path, robots.crate(arm_mesh=str(stl)))
    results = model_results(path, collision="mesh")
    assert failing(results) == {"mesh_complexity"}
    assert results["mesh_complexity"].value == 20480
    assert "'arm'" in results["mesh_complexity"].hints[0]


def test_2000_triangle_collision_mesh_warns(tmp_path):
    stl = robots.dense_sphere_stl(tmp_path, subdivisions=3)  # 1,280 triangles
    path = robots.write(tmp_path, robots.crate(arm_mesh=str(stl)))
    assert model_results(path, collision="mesh")["mesh_complexity"].status is Status.WARN


def test_reversed_limits_and_zero_velocity_fail_joint_definitions(tmp_path):
    path = robots.write(tmp_path, robots.crate(elbow_limit=(1.0, -1.0), elbow_velocity=0.0))
    results = model_results(path)
    assert failing(results) == {"joint_definitions"}
    hints = results["joint_definitions"].hints
    assert any("'elbow'" in h and "lower=1 upper=-1" in h for h in hints), hints
    assert any("'elbow'" in h and "velocity=0" in h for h in hints), hints


def test_declared_but_unenforced_limit_fails_joint_definitions(tmp_path):
    results = model_results(robots.unenforced_limit_mjcf(tmp_path))
    assert failing(results) == {"joint_definitions"}
    assert "'elbow'" in results["joint_definitions"].hints[0]


@pytest.mark.parametrize(
    ("shape", "size", "volume", "trace_per_mass"),
    [
        ("sphere", "0.1", 4 / 3 * math.pi * 0.1**3, 3 * 0.4 * 0.01),
        ("box", "0.1 0.2 0.3", 8 * 0.1 * 0.2 * 0.3, 2 * (0.01 + 0.04 + 0.09) / 3),
        ("cylinder", "0.1 0.2", math.pi * 0.01 * 0.4, 0.01 / 2 + 2 * (3 * 0.01 + 0.16) / 12),
    ],
)
def test_geometry_solid_matches_mujoco_inertia_from_density(shape, size, volume, trace_per_mass):
    import mujoco
    import numpy as np

    from twin_cli.validate.checks.geometry import geom_solid

    xml = f"""<mujoco><worldbody><body><freejoint/>
      <geom type="{shape}" size="{size}" density="1000"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    solid = geom_solid(model, 0)
    assert math.isclose(solid.volume, volume, rel_tol=1e-9), "volume [m³]"
    assert math.isclose(solid.trace_per_mass, trace_per_mass, rel_tol=1e-9), "trace(I)/m [m²]"
    # MuJoCo's own inertia from density is the independent side of the oracle.
    mujoco_trace = float(np.sum(model.body_inertia[1]) / model.body_mass[1])
    assert math.isclose(solid.trace_per_mass, mujoco_trace, rel_tol=1e-6), "vs MuJoCo"


# Corpus robots: model-check failures their upstream files really have. Conversions come from
# the shared session fixture (hull collision; inertia repaired only for the robots whose upstream
# inertias are non-physical, whose repairs then count as failures). Absent: passes every check.
CORPUS_EXPECTED_FAILURES: dict[str, set[str]] = {
    # Kinematic-only ROS-Industrial description: no <inertial> on any link (the repair gave each
    # moving link a mass) and effort="0" on every joint's <limit>.
    "abb_irb2400_12_155": {"inertial", "joint_definitions"},
    # depth_camera_*_camera breaks the triangle inequality and 'hatch' is singular upstream.
    "anymal_c": {"inertia_tensor"},
    # Placeholder tensors upstream: base_link and the *_foot links (all six entries equal).
    "hyq": {"inertia_tensor"},
    # gripper_link / gripper_link_sub weigh 0.001 kg upstream for ~100 cm³ (≈ 10 kg/m³); its
    # Gazebo file puts the RealSense 'intel_realsense_r200' on 'camera_link', which the robot
    # does not have (Gazebo drops the camera, and the tag with it).
    "open_manipulator_x": {"inertia_plausible", "sensor_links", "ignored_parts"},
    # Its xacro writes <gazebo reference="stick_link"> for a link it does not have.
    "aliengo": {"ignored_parts"},
    # franka_ros' gazebo:=true arm self-collides at its zero posture (link7 41 mm inside link5),
    # as it would in Gazebo; its launch file spawns it at a ready posture instead.
    "franka_panda": {"initial_overlap"},
}


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_model_checks(robot_id, converted_corpus):
    done = converted_corpus(robot_id)
    robot = robot_from_conversion(done, CORPUS[robot_id]["entry"], repair_inertia=False)
    results = {n: run_check(robot, _model_scenario(n), debug=True) for n in MODEL_CHECKS}
    expected = CORPUS_EXPECTED_FAILURES.get(robot_id, set())
    assert failing(results) == expected, {n: r.hints[:3] for n, r in results.items() if r.failed}
