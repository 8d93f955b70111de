"""Scenario TOML parsing: the bundled checklist loads, mistakes name the file, key and fix."""

from __future__ import annotations

import math
import sys

import pytest

from twin_cli.errors import ScenarioError, UnknownCheckError
from twin_cli.validate.checks import CHECKS, MODEL_CHECKS
from twin_cli.validate.runner import plan
from twin_cli.validate.scenario import builtin_names, load_builtin, load_scenario, resolve


def write(tmp_path, text: str, name: str = "mine.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_every_bundled_scenario_loads_and_names_a_registered_check():
    scenarios = load_builtin()
    assert [s.name for s in scenarios] == sorted(s.name for s in scenarios)
    assert len(scenarios) == len(builtin_names()) >= 11
    for sc in scenarios:
        assert sc.check in CHECKS, f"{sc.source}: check {sc.check!r} is not registered"
        unknown = set(sc.thresholds) - set(CHECKS[sc.check].defaults)
        assert not unknown, f"{sc.source}: unknown thresholds {unknown}"


def test_builtin_checklist_covers_every_physics_check():
    covered = {sc.check for sc in load_builtin()}
    physics = {c.name for c in CHECKS.values() if c.kind == "physics"}
    assert physics <= covered, f"physics checks without a bundled scenario: {physics - covered}"


def test_incline_tilts_gravity_by_theta(tmp_path):
    path = write(tmp_path, 'check = "gravity"\n[world]\ngravity = "earth"\nincline_deg = 30\n')
    gx, gy, gz = load_scenario(path).world.gravity_vector()
    assert math.isclose(math.hypot(gx, gz), 9.81, rel_tol=1e-12), "|g| must not change"
    assert math.isclose(math.degrees(math.atan2(-gx, -gz)), 30.0, rel_tol=1e-12), "tilt angle"
    assert gy == 0.0


def test_name_defaults_to_the_file_stem_and_thresholds_are_read(tmp_path):
    path = write(tmp_path, 'check = "gravity"\n[thresholds]\nrel_tol = 0.5\n', "drop.toml")
    sc = load_scenario(path)
    assert sc.name == "drop" and sc.thresholds == {"rel_tol": 0.5}


@pytest.mark.parametrize(
    ("text", "key", "fix"),
    [
        ('check = "gravity"\nduraton = 1\n', "duraton", "spelling"),
        ('check = "gravity"\n[world]\ngravity = "jupiter"\n', "world.gravity", "earth"),
        ('check = "gravity"\nduration = -1\n', "duration", "documented"),
        ("duration = 1\n", "check", "add this key"),
        ('check = "gravity"\n[[actions]]\nkind = "teleport"\n', "actions.0.kind", "documented"),
        ('check = "gravity"\n[[obstacles]]\nsize = [1, 0, 1]\n', "obstacles.0.size", "documented"),
    ],
)
def test_bad_scenario_names_file_key_and_fix(tmp_path, text, key, fix):
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    message = str(err.value)
    assert str(path) in message and key in message and fix in message, message


def test_bad_toml_syntax_is_a_scenario_error(tmp_path):
    path = write(tmp_path, "check = \n")
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scenario(path)


def test_unknown_check_and_threshold_are_named_with_valid_choices(tmp_path):
    bad_check = write(tmp_path, 'check = "levitation"\n', "a.toml")
    with pytest.raises(ScenarioError, match="levitation.*gravity"):
        plan([str(bad_check)])
    bad_key = write(tmp_path, 'check = "gravity"\n[thresholds]\ntolerance = 1\n', "b.toml")
    with pytest.raises(ScenarioError, match=r"thresholds\.tolerance.*rel_tol"):
        plan([str(bad_key)])
    with pytest.raises(UnknownCheckError, match="levitation.*gravity"):
        plan(only=["levitation"])


def test_resolve_finds_bundled_names_and_rejects_unknown_ones():
    assert resolve("free_fall").check == "gravity"
    with pytest.raises(ScenarioError, match="free_fall"):
        resolve("no_such_scenario")


def test_plan_keeps_model_checks_and_filters_with_only_and_skip(tmp_path):
    everything = [sc.check for sc in plan()]
    assert everything[: len(MODEL_CHECKS)] == MODEL_CHECKS
    assert [sc.check for sc in plan(only=["gravity"])] == ["gravity"]
    assert "stability" not in [sc.check for sc in plan(skip=["stability"])]
    mine = write(tmp_path, 'check = "mesh_complexity"\n[thresholds]\nmax_triangles = 5\n')
    planned = plan([str(mine)])
    assert [sc.check for sc in planned].count("mesh_complexity") == 1
    assert planned[-1].thresholds == {"max_triangles": 5.0}


def test_parsing_scenarios_does_not_import_mujoco():
    assert "twin_cli.validate.scenario" in sys.modules
    code = (
        "import sys, twin_cli.validate.scenario, twin_cli.validate.checks; "
        "print('mujoco' in sys.modules)"
    )
    import subprocess

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False", "scenario parsing must stay light"


PINCER_HOLD = """
name = "pincer_hold"
check = "ground_contact"
duration = 0.5
[robot]
joints = {{ lead = {lead} }}
[hold]
kp = 300.0
kd = 10.0
"""


def test_robot_joints_set_the_start_posture_that_the_hold_holds(tmp_path):
    from models import mimic_pincer, write_urdf

    from twin_cli.validate.checks.sim import ScenarioRun
    from twin_cli.validate.robot import load_robot

    robot = load_robot(write_urdf(tmp_path, mimic_pincer(offset=0.2, multiplier=-1.0)))
    run = ScenarioRun(robot, load_scenario(write(tmp_path, PINCER_HOLD.format(lead=0.6))))
    held = dict(zip([j.name for j in run.joints], run.q_hold, strict=True))
    assert held == pytest.approx({"lead": 0.6, "follow": -0.4}, abs=1e-12), "start posture"
    run.run(0.5)
    lead = float(run.qpos()[next(j.qpos for j in run.joints if j.name == "lead")])
    # Gravity on the 0.5 kg finger (centre 0.1 m out) vs the PD: steady error ≈ m·g·r·cos q/kp.
    sag = 0.5 * 9.81 * 0.1 * math.cos(0.6) / 300.0
    assert abs(lead - 0.6) < 3 * sag, f"held lead {lead:.4f} rad; PD sag ≈ {sag:.4f} rad"


def test_unknown_or_out_of_range_robot_joints_is_a_scenario_error_before_any_check(tmp_path):
    from models import mimic_pincer, write_urdf

    from twin_cli.validate.runner import validate

    urdf = write_urdf(tmp_path, mimic_pincer())
    path = write(tmp_path, PINCER_HOLD.format(lead=2.0))
    with pytest.raises(ScenarioError) as caught:
        validate(urdf, scenarios=[str(path)])
    message = str(caught.value)
    for part in (str(path), "robot.joints", "[lead]", "[-1, 1] rad"):
        assert part in message, f"message lacks {part!r}: {message}"
