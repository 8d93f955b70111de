"""Broken robots fail the check meant for their flaw, each message names the part and a fix that
works (applied, the robot passes), and a check that cannot apply is not applicable, not failed.

Robots are written by the tests (`validate_robots`); verdicts go through `twin validate` (exit
code, JSON, JUnit) or the runner, with real physics and oracles computed here.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import validate_robots as robots

from twin_cli.validate.checks.base import Status
from twin_cli.validate.runner import validate

TWIN = Path(sys.executable).parent / "twin"
G = 9.81  # [m/s²] MuJoCo's default gravity, the robot compiled alone


def twin(*args: object) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(TWIN), "validate", *map(str, args)], capture_output=True, text=True, timeout=120
    )


def by_check(report: dict) -> dict[str, dict]:
    return {c["check"]: c for c in report["checks"]}


def test_pendulum_too_weak_to_hold_itself_fails_gravity_hold_with_the_effort_that_holds_it(
    tmp_path,
):
    """1 kg at 0.5 m: m·g·L·cos q is 4.3-4.9 N m over ±0.5 rad; 0.01 N m holds it nowhere."""
    path = robots.write(tmp_path, robots.pendulum(effort=0.01), "weak.urdf")
    done = twin(path, "--json")
    assert done.returncode == 1, done.stdout + done.stderr
    report = json.loads(done.stdout)
    checks = by_check(report)
    assert report["counts"]["error"] == 0, [c["measured"] for c in report["checks"]]
    hold = checks["gravity_hold"]
    assert hold["status"] == "fail", hold
    (hint,) = hold["hints"]
    assert "joint 'shoulder'" in hint and "link 'bob'" in hint and "0.01 N m" in hint, hint
    level = robots.PENDULUM_MASS * G * robots.PENDULUM_LENGTH  # the largest load: level
    needed = float(re.search(r"at least ([0-9.]+) N m", hint).group(1))
    assert math.isclose(needed, level, rel_tol=2e-3), f"effort asked {needed} N m, m·g·L {level}"
    assert checks["tracking"]["status"] == "fail", "0.01 N m cannot follow the 1 Hz sine either"
    assert "sine tracking error" in " ".join(checks["tracking"]["hints"])


def test_pendulum_with_the_asked_effort_holds_everywhere_and_tracks(tmp_path):
    from twin_cli.validate.checks.model_effort import SAMPLES

    level = robots.PENDULUM_MASS * G * robots.PENDULUM_LENGTH
    effort = round(level + 0.01, 2)
    path = robots.write(tmp_path, robots.pendulum(effort=effort), "fixed.urdf")
    run = validate(path, only=["gravity_hold", "tracking"])
    for outcome in run.results:
        assert outcome.status is Status.PASS, (outcome.check, outcome.measured, outcome.hints)
    # The smallest load, m·g·L·cos q, is at the outermost sample: half a step inside the stop.
    outermost = robots.PENDULUM_RANGE * (1.0 - 1.0 / SAMPLES)
    hold = next(r for r in run.results if r.check == "gravity_hold")
    expected = effort / (level * math.cos(outermost))
    assert math.isclose(hold.value, expected, rel_tol=1e-6), f"effort / load {hold.value}"


def test_lidar_on_a_missing_link_fails_sensor_links_listing_the_links(tmp_path):
    path = robots.write(tmp_path, robots.scout(lidar_link="lidar_linkk"), "typo.urdf")
    junit = tmp_path / "v.xml"
    only = ["--only", "sensor_links", "--only", "sensor_lidar"]
    done = twin(path, *only, "--json", "--junit", junit)
    assert done.returncode == 1, done.stdout + done.stderr
    checks = by_check(json.loads(done.stdout))
    (hint,) = checks["sensor_links"]["hints"]
    for part in ("sensor 'front_lidar'", "link 'lidar_linkk'", "base, lidar_link"):
        assert part in hint, f"{part!r} not named: {hint}"
    lidar = checks["sensor_lidar"]
    assert lidar["status"] == "skip" and "lidar_linkk" in lidar["details"][0], lidar
    failed = ET.parse(junit).getroot().findall("testsuite/testcase/failure/..")
    assert [case.get("name") for case in failed] == ["sensor_links"]
    fixed = robots.write(tmp_path, robots.scout(), "fixed.urdf")  # the reference the hint names
    run = validate(fixed, only=["sensor_links", "sensor_lidar"])
    assert [r.status for r in run.results] == [Status.PASS, Status.PASS], run.results


@pytest.mark.parametrize("kp", [None, 1e6])
def test_an_imu_resting_on_gazebos_contacts_reads_its_declared_noise(tmp_path, kp):
    """A box on Gazebo's rigid default contact (kp 1e12), or on kp 1e6 with kd 1, rests without
    ringing, as in Gazebo: its IMU, declaring 1e-4 m/s², spreads within 20 % of that (the
    contacts used to ring at the rigid default: thousands of σ)."""
    path = robots.write(tmp_path, robots.imu_box(kp=kp), "resting.urdf")
    (outcome,) = validate(path, only=["sensor_imu"]).results
    assert outcome.status is Status.PASS, (outcome.measured, outcome.hints)
    ratio = float(re.search(r"noise ([0-9.e+-]+)× declared", outcome.measured).group(1))
    assert ratio <= 1.2, f"spread over declared noise {ratio}"


def test_arm_folded_onto_itself_fails_initial_overlap_unless_started_apart(tmp_path):
    path = robots.write(tmp_path, robots.folded_arm(), "folded.urdf")
    folded = twin(path, "--only", "initial_overlap", "--json")
    assert folded.returncode == 1, folded.stdout + folded.stderr
    (check,) = json.loads(folded.stdout)["checks"]
    (hint,) = check["hints"]
    depth = f"{robots.FOLD_DEPTH * 1000:.3g} mm"
    assert "'hand' and 'upper'" in hint and f"overlap by {depth}" in hint, hint
    assert "remove <selfCollide> from link 'hand'" in hint and "-J" in hint, hint
    # -J reaches the model check: the hand hung down is clear of every link.
    apart = twin(path, "--only", "initial_overlap", "-J", "wrist=-1.5", "--json")
    assert apart.returncode == 0, apart.stdout + apart.stderr
    # The named tag removed: the pair no longer collides (listed as a latent overlap only).
    untagged = robots.folded_arm().replace("<selfCollide>true</selfCollide>", "")
    run = validate(robots.write(tmp_path, untagged, "untagged.urdf"), only=["initial_overlap"])
    (outcome,) = run.results
    assert outcome.status is Status.WARN and "do not collide" in outcome.details[0], outcome


def test_frictionless_casters_make_friction_incline_not_applicable_in_junit(tmp_path):
    path = robots.write(tmp_path, robots.caster_base(mu=0.0), "casters.urdf")
    junit = tmp_path / "v.xml"
    done = twin(path, "--only", "friction_incline", "--junit", junit)
    assert done.returncode == 0, done.stdout + done.stderr
    suite = ET.parse(junit).getroot().find("testsuite")
    assert (suite.get("failures"), suite.get("errors"), suite.get("skipped")) == ("0", "0", "1")
    (skipped,) = suite.findall("testcase/skipped")
    reason = skipped.get("message")
    assert "frictionless" in reason and "caster_front" in reason, reason
    # With μ = 1 the same base is probed: it sticks at tan θ = 0.8 and slides at 1.25.
    run = validate(robots.write(tmp_path, robots.caster_base(mu=1.0), "grip.urdf"),
                   only=["friction_incline"])  # fmt: skip
    assert run.results[0].status is Status.PASS, run.results[0].hints
