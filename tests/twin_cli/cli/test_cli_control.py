"""`twin command`, `twin joints`, `twin trajectory` against a served world, as a user types them."""

from __future__ import annotations

import json

import pytest
from models import CONTROL_RIG as WHEEL_URDF
from test_cli_world import Twin


@pytest.fixture
def rig(tmp_path):
    t = Twin(tmp_path / "rt")
    (tmp_path / "rig.urdf").write_text(WHEEL_URDF)
    t("spawn", str(tmp_path / "rig.urdf"), "--name", "rig", "-z", "1")
    t("pause")
    yield t, tmp_path
    t("stop", check=False, timeout=60)


def _joints(t: Twin) -> dict:
    return {j["name"]: j for j in json.loads(t("joints", "rig", "--json").stdout)}


def test_command_holds_a_target_and_joints_shows_its_mode(rig):
    t, _ = rig
    t("command", "rig", "slide=0.2")
    t("step", "3000")
    slide = _joints(t)["slide"]
    assert slide["mode"] == "position" and slide["target"] == 0.2, slide
    assert slide["position"] == pytest.approx(0.2, abs=1e-3), "the servo reached 0.2 m"
    t("command", "rig", "spin=1.5", "--mode", "velocity")
    t("step", "500")
    assert _joints(t)["spin"]["velocity"] == pytest.approx(1.5, rel=0.05), "velocity servo"


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["command", "nobody", "slide=0.1"], "nobody"),
        (["command", "rig", "elbow=0.1"], "elbow"),
        (["command", "rig", "slide=0.1", "--mode", "torque"], "torque"),
        (["command", "rig", "slide=0.35"], "outside [-0.2, 0.3]"),  # the joint's range
        (["command", "rig", "spin=2", "--mode", "position"], "offer only effort, velocity"),
        (["command", "rig", "slide"], "JOINT=VALUE"),
    ],
)
def test_bad_command_exits_2_with_one_message_and_leaves_the_world_unchanged(rig, args, words):
    t, _ = rig
    before = _joints(t)
    done = t(*args, check=False)
    assert done.returncode == 2, f"exit {done.returncode}: {done.stderr}"
    assert words in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, f"one message: {done.stderr!r}"
    assert _joints(t) == before, "joints (modes, targets, state) unchanged"


def test_trajectory_is_followed_and_bad_files_exit_2(rig):
    t, tmp_path = rig
    good = tmp_path / "slide.csv"
    good.write_text("time_from_start,slide\n0.5,0.05\n1.0,0.1\n1.5,0.12\n2.0,0.1\n2.5,0.0\n")
    t("resume")
    report = json.loads(t("trajectory", "rig", str(good), "--json", timeout=60).stdout)
    assert not report["active"] and report["elapsed"] == pytest.approx(2.5, abs=1e-6), report
    assert report["max_error"]["slide"] < 0.02, f"tracking error {report['max_error']}"
    t("pause")
    before = _joints(t)
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "joint_names: [slide]\npoints:\n  - {positions: [0.1], time_from_start: 1}\n"
        "  - {positions: [0.2], time_from_start: 0.5}\n"
    )
    done = t("trajectory", "rig", str(bad), check=False)
    assert done.returncode == 2 and "not after 1 s" in done.stderr, done.stderr
    assert _joints(t) == before, "a refused trajectory leaves the world unchanged"


def test_a_waypoint_just_past_a_limit_is_clamped_and_the_report_says_by_how_much(rig):
    """slide's range ends at 0.3 m: a waypoint at 0.305 m (within the 0.0087 m tolerance) is
    followed to 0.3 m, and both the JSON and the table name the 0.005 m move."""
    t, tmp_path = rig
    path = tmp_path / "past.csv"
    path.write_text("time_from_start,slide\n0.5,0.305\n")
    t("resume")
    report = json.loads(t("trajectory", "rig", str(path), "--json", timeout=60).stdout)
    assert report["clamped"]["slide"] == pytest.approx(0.005, abs=1e-12), report
    table = t("trajectory", "rig", str(path), timeout=60).stdout
    assert "clamped onto limit" in table and "0.005" in table, table
    t("pause")
    assert _joints(t)["slide"]["target"] == pytest.approx(0.3, abs=1e-6), "held at the limit"


def test_command_and_trajectory_import_no_physics(rig):
    from test_lazy_imports import HEAVY, _imported

    t, tmp_path = rig
    path = tmp_path / "one.csv"
    path.write_text("time_from_start,slide\n0.01,0.0\n")
    for args in (["command", "rig", "slide=0.1"], ["trajectory", "rig", str(path), "--no-wait"]):
        proc, modules = _imported(args, t.env)
        assert proc.returncode == 0, f"twin {args}: {proc.stderr[-500:]}"
        assert not modules & set(HEAVY), f"twin {args} imported {modules & set(HEAVY)}"
