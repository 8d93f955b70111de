"""`twin validate` end to end: exit codes, JUnit/JSON/Markdown/PNG reports, user scenarios."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib.image
import pytest
import validate_robots as robots  # noqa: E402

import scenarios  # noqa: E402
from twin_cli.validate.checks import CHECKS, MODEL_CHECKS  # noqa: E402
from twin_cli.validate.scenario import builtin_names  # noqa: E402

TWIN = Path(sys.executable).parent / "twin"


HANG_S = 600  # [s] a hang guard, not a budget: a validate run takes 30 s quiet, 100+ s on a
# runner shared with two busy processes per core


def twin(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(TWIN), "validate", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        cwd=cwd,
    )


def statuses(report: dict) -> dict[str, str]:
    return {f"{c['check']} ({c['scenario']})": c["status"] for c in report["checks"]}


@pytest.mark.timeout(3 * HANG_S)  # two validate runs
def test_humanoid_passes_every_check_and_writes_every_report(tmp_path):
    """Every report written, and the verdicts those reports (and a recording) leave unchanged:
    the same statuses as a run that writes nothing."""
    junit, md, plots, bags = (tmp_path / n for n in ("v.xml", "v.md", "plots", "bags"))
    done = twin(
        scenarios.HUMANOID, "--junit", junit, "--markdown", md, "--plots", plots,
        "--record", bags, "--json",
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    report = json.loads(done.stdout)
    expected = len(MODEL_CHECKS) + len(builtin_names())
    assert report["passed"] and len(report["checks"]) == expected
    assert report["exit_code"] == 0 and report["counts"]["error"] == 0, report["counts"]
    assert {c["check"] for c in report["checks"]} == set(CHECKS), "every check ran"
    suite = ET.parse(junit).getroot().find("testsuite")
    cases = suite.findall("testcase")
    assert int(suite.get("tests")) == len(cases) == expected, "JUnit counts the checks that ran"
    assert int(suite.get("failures")) == 0 and not suite.findall("testcase/failure")
    assert int(suite.get("errors")) == 0 and not suite.findall("testcase/error")
    skipped = suite.findall("testcase/skipped")
    assert int(suite.get("skipped")) == len(skipped) and all(s.get("message") for s in skipped)
    assert "twin validate: `humanoid` passed" in md.read_text()
    assert_one_embedded_plot_per_physics_check(report["checks"], md.read_text(), plots)
    assert (bags / "realtime.mcap").is_file(), "the realtime scenario is recorded too"
    quiet = twin(scenarios.HUMANOID, "--json")
    assert statuses(json.loads(quiet.stdout)) == statuses(report), "reports changed a verdict"


def assert_one_embedded_plot_per_physics_check(checks: list[dict], text: str, plots: Path):
    """Every physics check that ran has at least one PNG, a readable image, embedded in the
    Markdown (`![check ...](plots/NAME.png)`); no PNG is left unembedded or half-written."""
    embedded: dict[str, set[str]] = {}
    for line in text.splitlines():
        if line.startswith("![") and "](plots/" in line:
            check = line[2:].split(":")[0].split(" (")[0]
            embedded.setdefault(check, set()).add(line.split("](plots/")[1].rstrip(")"))
    physics = {c["check"] for c in checks if c["kind"] == "physics" and c["status"] != "skip"}
    assert physics and set(embedded) == physics, (sorted(embedded), sorted(physics))
    files = {p.name for p in plots.iterdir()}
    assert files == set().union(*embedded.values()), "every file embedded, no .tmp left"
    for name in files:
        image = matplotlib.image.imread(plots / name)  # a valid PNG decodes
        assert image.shape[0] >= 300 and image.shape[1] >= 500, (name, image.shape)


BROKEN = [
    ("no_inertial", {"arm_inertial": False}, ["--only", "inertial"], "inertial", "'arm'"),
    (
        "tiny_inertia",
        {"arm_mass": 5.0, "arm_inertia": 1e-9},
        ["--only", "inertia_plausible"],
        "inertia_plausible",
        "too small for this mass",
    ),
    (
        "overlap",
        {"flap_overlaps_arm": True, "arm_self_collide": True},
        ["--only", "initial_overlap"],
        "initial_overlap",
        "'arm' and 'flap'",
    ),
    (
        "soft_kp",
        {"kp": 1000.0},
        ["--only", "ground_contact"],
        "ground_contact",
        "kp 1e+03 N/m is too soft for the load on it",
    ),
]


@pytest.mark.parametrize(("label", "flaw", "options", "check", "hint"), BROKEN, ids=lambda v: v)
def test_broken_robot_fails_the_right_check_with_exit_1(
    tmp_path, label, flaw, options, check, hint
):
    path = robots.write(tmp_path, robots.crate(**flaw), f"{label}.urdf")
    junit = tmp_path / "junit.xml"
    done = twin(path, *options, "--junit", junit)
    assert done.returncode == 1, done.stdout + done.stderr
    assert hint in done.stdout, done.stdout
    failures = ET.parse(junit).getroot().findall("testsuite/testcase/failure/..")
    assert [case.get("name") for case in failures] == [check]


def test_dense_collision_mesh_fails_in_mesh_mode(tmp_path):
    stl = robots.dense_sphere_stl(tmp_path, subdivisions=5)
    path = robots.write(tmp_path, robots.crate(arm_mesh=str(stl)))
    done = twin(path, "--collision", "mesh", "--only", "mesh_complexity", "--json")
    assert done.returncode == 1, done.stderr
    (result,) = json.loads(done.stdout)["checks"]
    assert result["status"] == "fail" and result["value"] == 20480
    assert "20480 triangles" in result["hints"][0]


def test_unenforced_joint_limit_fails_joint_limits(tmp_path):
    done = twin(robots.unenforced_limit_mjcf(tmp_path), "--only", "joint_limits")
    assert done.returncode == 1, done.stdout + done.stderr
    assert "joint 'elbow' goes" in done.stdout and "not enforced" in done.stdout


def test_user_scenario_thresholds_decide_pass_or_fail(tmp_path):
    robot = robots.write(tmp_path, robots.crate(kp=1000.0))
    text = (Path(scenarios.SCENARIO_DIR) / "ground_contact.toml").read_text()
    lenient = tmp_path / "lenient.toml"
    lenient.write_text(text.replace("max_penetration_m = 0.005", "max_penetration_m = 0.03"))
    strict = tmp_path / "strict.toml"
    strict.write_text(text.replace("max_penetration_m = 0.005", "max_penetration_m = 0.01"))
    ok = twin(robot, "--scenario", lenient, "--skip", "inertia_plausible", "--json")
    assert ok.returncode == 0, ok.stdout + ok.stderr
    ran = [c["check"] for c in json.loads(ok.stdout)["checks"]]
    assert ran[-1] == "ground_contact" and ran.count("gravity") == 0, "only the given scenario"
    bad = twin(robot, "--scenario", strict, "--only", "ground_contact")
    assert bad.returncode == 1 and "limit 10 mm" in bad.stdout, bad.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["no_such_robot.urdf"], "no such file"),
        (["no_such_robot.xml"], "no_such_robot.xml: no such file"),
        ([str(scenarios.HUMANOID), "--only", "levitation"], "unknown validation check"),
        ([str(scenarios.HUMANOID), "--scenario", "nope"], "no such scenario"),
        ([str(scenarios.HUMANOID), "--arg", "foot_mu"], "NAME:=VALUE"),
    ],
)
def test_malformed_input_exits_2_with_a_message(args, needle):
    done = twin(*args)
    assert done.returncode == 2, done.stdout + done.stderr
    assert needle in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_malformed_mjcf_exits_2_naming_the_file_and_the_line(tmp_path):
    robot = tmp_path / "broken.xml"
    robot.write_text('<mujoco><worldbody><body><geom size="0.1"/></worldbody></mujoco>')
    done = twin(robot)
    assert done.returncode == 2, done.stdout + done.stderr
    assert "broken.xml: not valid MJCF" in done.stderr and "Line number=1" in done.stderr
    assert "Traceback" not in done.stderr and "internal error" not in done.stderr, done.stderr


def test_malformed_scenario_file_exits_2_naming_file_and_key(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('check = "gravity"\n[world]\ngravty = "moon"\n')
    done = twin(scenarios.HUMANOID, "--scenario", bad)
    assert done.returncode == 2 and str(bad) in done.stderr and "world.gravty" in done.stderr


def test_validate_command_module_imports_nothing_heavy():
    code = (
        "import sys, twin_cli.cli.commands.validate; "
        "print(sorted(m for m in ('mujoco', 'numpy', 'trimesh', 'matplotlib') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]", done.stdout


def test_start_posture_out_of_range_or_unknown_exits_2_naming_the_joint():
    bad_range = twin(scenarios.HUMANOID, "-J", "left_knee=3.0", "--only", "friction_standing")
    assert bad_range.returncode == 2, bad_range.stdout + bad_range.stderr
    assert "left_knee" in bad_range.stderr and "2.2" in bad_range.stderr, bad_range.stderr
    unknown = twin(scenarios.HUMANOID, "-J", "left_tail=0.1", "--only", "friction_standing")
    assert unknown.returncode == 2, unknown.stdout + unknown.stderr
    assert "left_tail" in unknown.stderr and "left_knee" in unknown.stderr, unknown.stderr
    assert "Traceback" not in bad_range.stderr + unknown.stderr


def test_start_posture_reaches_the_standing_check():
    """A crouch is held and passes; a 0.7 rad ankle lean puts the COM outside the feet and
    fails, which it can only do if -J reached the robot (upright, it passes)."""

    def standing(*postures: str) -> subprocess.CompletedProcess:
        flags = [arg for item in postures for arg in ("-J", item)]
        return twin(scenarios.HUMANOID, *flags, "--only", "friction_standing", "--json")

    crouch = standing(
        "left_hip=-0.3", "right_hip=-0.3", "left_knee=0.6", "right_knee=0.6",
        "left_ankle=-0.3", "right_ankle=-0.3",
    )  # fmt: skip
    assert crouch.returncode == 0, crouch.stdout + crouch.stderr
    lean = standing("left_ankle=0.7", "right_ankle=0.7")
    assert lean.returncode == 1, lean.stdout + lean.stderr
    (check,) = json.loads(lean.stdout)["checks"]
    assert check["value"] > 0.05, f"leaning robot slipped only {check['value']} m"
    assert "tips over" in " ".join(check["hints"]), check["hints"]


@pytest.mark.parametrize("kind", ["directory", "fifo"])
def test_a_report_target_that_is_not_a_regular_file_exits_2_before_any_check(tmp_path, kind):
    """`--junit` naming a directory or a pipe is refused at once, naming it, and left as it was
    (a rename over it would have replaced it; a write to a pipe with no reader would hang)."""
    target = tmp_path / "report.xml"
    if kind == "directory":
        target.mkdir()
        (target / "kept").write_text("x")
    else:
        os.mkfifo(target)
    done = twin(scenarios.HUMANOID, "--junit", target)
    assert done.returncode == 2, done.stdout + done.stderr
    assert "report.xml" in done.stderr and "regular file" in done.stderr, done.stderr
    assert "Traceback" not in done.stderr and "humanoid" not in done.stdout, "no check ran"
    if kind == "directory":
        assert (target / "kept").read_text() == "x"
    else:
        assert stat.S_ISFIFO(target.lstat().st_mode)


def test_reports_are_written_atomically_and_readable_by_others(tmp_path):
    junit = tmp_path / "r" / "v.xml"
    junit.parent.mkdir()
    done = twin(scenarios.HUMANOID, "--only", "inertial", "--junit", junit)
    assert done.returncode == 0, done.stdout + done.stderr
    assert ET.parse(junit).getroot().find("testsuite") is not None
    assert stat.S_IMODE(junit.stat().st_mode) == 0o644
    assert sorted(p.name for p in junit.parent.iterdir()) == ["v.xml"], "no temporary file left"
