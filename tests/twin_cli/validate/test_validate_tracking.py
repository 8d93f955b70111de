"""`twin validate`'s tracking check on real robots: it passes where the servos can follow and
names the joint where its limits cannot (a position step and a 1 Hz sine, scenarios/tracking)."""

from __future__ import annotations

import pytest
from corpus_registry import CORPUS, corpus_ids
from models import CONTROL_RIG, write_urdf

from twin_cli.validate.checks.base import Status
from twin_cli.validate.robot import robot_from_conversion
from twin_cli.validate.runner import run_check
from twin_cli.validate.scenario import load_builtin


@pytest.fixture(scope="module")
def tracking():
    return next(s for s in load_builtin() if s.check == "tracking")


@pytest.mark.parametrize("robot_id", corpus_ids(["ur5e", "anymal_c"]))
def test_corpus_robot_tracks_a_step_and_a_sine_within_its_limits(
    robot_id, tracking, converted_corpus
):
    robot = robot_from_conversion(
        converted_corpus(robot_id), CORPUS[robot_id]["entry"], repair_inertia=True
    )
    outcome = run_check(robot, tracking, debug=True)
    others = [h for h in outcome.hints if "has no speed limit" not in h]
    assert outcome.status in (Status.PASS, Status.WARN) and not others, (
        f"{robot_id}: {outcome.status}, {outcome.measured}; {outcome.hints}"
    )
    assert outcome.value < 0.2, f"{robot_id}: sine error {outcome.value:.1%} of its amplitude"


def test_a_joint_too_weak_to_follow_fails_naming_it(tmp_path, tracking):
    from converters.pipeline import convert_full

    # The rig's slider (0.5 kg) with 0.05 N instead of 50 N: at most 0.1 m/s², so in half a
    # 1 Hz period it moves at most ½·0.1·0.5² = 12.5 mm, against the sine's 2 × 62.5 mm swing:
    # its error is at least (125 − 12.5)/2 mm, 90 % of the amplitude (threshold 20 %).
    weak = CONTROL_RIG.replace('effort="50"', 'effort="0.05"')
    done = convert_full(write_urdf(tmp_path, weak))
    outcome = run_check(
        robot_from_conversion(done, "rig.urdf", repair_inertia=False), tracking, debug=True
    )
    assert outcome.status is Status.FAIL, f"{outcome.status}: {outcome.measured}"
    assert outcome.value > 0.9, f"sine error {outcome.value:.1%} of the amplitude, expected > 90 %"
    sine = [h for h in outcome.hints if "joint 'slide'" in h and "sine tracking error" in h]
    assert sine and "<limit effort>" in sine[0], outcome.hints
    assert any("joint 'slide'" in h and "settles" in h for h in outcome.hints), outcome.hints
    assert not any("spin" in h for h in outcome.hints), "the disc has no position interface"
