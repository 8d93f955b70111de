"""Real robots under `twin validate`: every corpus robot stands, rests and keeps its joint limits,
and no check crashes on any of them.

Each robot is converted once a session (`converted_corpus`: hull collisions, inertia repaired
only where upstream's is non-physical) and run through the built-in `stability`,
`ground_contact` and `joint_limits` scenarios with their stated thresholds (no contact energy
gain > 5 % of m·g·h, sink ≤ 5 mm and at rest ≤ 0.05 m/s after 1.5 s, ≤ 0.05 rad past a stop),
then through every other check of the checklist, which may pass, fail or not apply, never crash.
"""

from __future__ import annotations

import math

import pytest
from corpus_registry import CORPUS, corpus_ids

from twin_cli.validate.checks import MODEL_CHECKS
from twin_cli.validate.checks.base import Status
from twin_cli.validate.robot import robot_from_conversion
from twin_cli.validate.runner import plan, run_check
from twin_cli.validate.scenario import load_builtin, with_joints

CHECKS = ("stability", "ground_contact", "joint_limits")

# Failures that come from the upstream description, not from twin; each still runs without NaN.
UPSTREAM = {
    ("solo12", "joint_limits"): (
        "example-robot-data's solo12.urdf gives every joint effort 1000 N m, velocity 1000 rad/s "
        "and range ±10 rad (placeholders; Solo-12's motors give ~2.7 N m): 1000 N m on a "
        "5e-4 kg m² leg whirls the floating robot at ~1000 rad/s"
    ),
    ("aliengo", "ground_contact"): (
        "home posture = zeros clamped into the ranges: every knee sits on its -0.646 rad stop, "
        "80 % of the weight lands on the rear feet and the front feet (μ 0.6) slide at the "
        "friction-cone edge, so the robot drifts backwards (~0.9 m/s) instead of coming to rest; "
        "in a standing posture (-J, STANDING below) it passes"
    ),
    ("franka_panda", "stability"): (
        "franka_ros' gazebo:=true arm has <self_collide> on, and at its zero posture (joint4 "
        "clamped to -0.0698) link7 lies 41 mm inside link5: the contact pushes them apart "
        "(energy gain 5.2 % measured). Gazebo spawns it at its launch file's ready posture (-J), "
        "where it passes (READY below)"
    ),
}

# Start postures (`twin validate -J`, scenario `[robot] joints`) [rad] for robots whose home
# posture cannot stand. aliengo: hips 0, thighs 0.8, calves -1.5 (knees off their stops).
STANDING = {
    "aliengo": {
        f"{leg}_{part}_joint": value
        for leg in ("FR", "FL", "RR", "RL")
        for part, value in (("hip", 0.0), ("thigh", 0.8), ("calf", -1.5))
    },
}
# franka_gazebo's launch-file posture (its `initial_joint_positions` -J arguments) [rad].
READY = {
    "franka_panda": {
        "panda_joint2": -math.pi / 4,
        "panda_joint4": -3 * math.pi / 4,
        "panda_joint6": math.pi / 2,
        "panda_joint7": math.pi / 4,
        "panda_finger_joint1": 0.001,
    },
}


@pytest.fixture(scope="module")
def scenarios():
    return {s.check: s for s in load_builtin() if s.check in CHECKS}


def _cases():
    return [
        pytest.param(robot_id, check, id=f"{robot_id}-{check}")
        for robot_id in corpus_ids()
        for check in CHECKS
    ]


@pytest.mark.parametrize("robot_id, check", _cases())
def test_corpus_robot_passes_stability_contact_and_limit_checks(
    robot_id, check, converted_corpus, scenarios
):
    done = converted_corpus(robot_id)
    robot = robot_from_conversion(done, CORPUS[robot_id]["entry"], repair_inertia=True)
    outcome = run_check(robot, scenarios[check], debug=True)
    hints = " | ".join(outcome.hints)
    assert "NaN" not in hints, f"{robot_id} {check}: diverged: {hints}"
    assert outcome.value is None or math.isfinite(outcome.value), f"{robot_id} {check}: value"
    if (robot_id, check) in UPSTREAM:
        assert outcome.status is Status.FAIL, (
            f"{robot_id} {check} now passes: drop it from UPSTREAM ({outcome.measured})"
        )
        return
    assert outcome.status in (Status.PASS, Status.NOT_APPLICABLE), (
        f"{robot_id} {check}: {outcome.measured}; {hints}"
    )


@pytest.mark.parametrize("check", ["ground_contact", "friction_standing"])
def test_aliengo_stands_still_in_a_standing_start_posture(check, converted_corpus):
    # Measured in its home posture: friction_standing slip 1.56 m, ground_contact 0.91 m/s.
    done = converted_corpus("aliengo")
    robot = robot_from_conversion(done, CORPUS["aliengo"]["entry"], repair_inertia=True)
    scenario = with_joints(next(s for s in load_builtin() if s.check == check), STANDING["aliengo"])
    outcome = run_check(robot, scenario, debug=True)
    assert outcome.status is Status.PASS, f"aliengo {check}: {outcome.measured}; {outcome.hints}"


@pytest.mark.skipif("franka_panda" not in CORPUS, reason="corpus: no franka_panda entry")
@pytest.mark.parametrize("check", ["stability", "initial_overlap", "joint_limits"])
def test_franka_panda_passes_from_its_ready_posture(check, converted_corpus):
    done = converted_corpus("franka_panda")
    robot = robot_from_conversion(done, CORPUS["franka_panda"]["entry"], repair_inertia=True)
    scenario = next(s for s in plan() if s.check == check)
    outcome = run_check(robot, with_joints(scenario, READY["franka_panda"]), debug=True)
    assert outcome.status is Status.PASS, f"franka {check}: {outcome.measured}; {outcome.hints}"


# Run with debug=True on every corpus robot elsewhere (a crash raises there): the checks above,
# and the model checks in test_validate_model.
ALREADY_RUN = {*CHECKS, *MODEL_CHECKS}


@pytest.mark.parametrize("robot_id", corpus_ids())
def test_corpus_robot_runs_every_other_check_without_a_crash(robot_id, converted_corpus):
    robot = robot_from_conversion(
        converted_corpus(robot_id), CORPUS[robot_id]["entry"], repair_inertia=True
    )
    outcomes = [run_check(robot, sc) for sc in plan() if sc.check not in ALREADY_RUN]
    crashed = {r.check: [r.measured, *r.details] for r in outcomes if r.errored}
    assert not crashed, f"{robot_id}: checks crashed: {crashed}"
    for r in outcomes:  # a check that does not apply says why
        assert r.status is not Status.NOT_APPLICABLE or r.details, f"{robot_id} {r.check}"
