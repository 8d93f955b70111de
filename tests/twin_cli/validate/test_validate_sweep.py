"""`twin validate --sweep`: variants applied as Gazebo tags, Coulomb's threshold found on a pool
and on a real Ray cluster, reports, and bad input."""

from __future__ import annotations

import json
import math
import re
import socket
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from converters.gazebo.contact import SOFT_IMPEDANCE
from scenarios import SCENARIO_DIR
from twin_cli.validate.scenario import load_scenario
from twin_cli.validate.sweep import Axis, Task, load_variant, parse_axis, run_task, sweep

HUMANOID = SCENARIO_DIR / "robots" / "humanoid.urdf.xacro"
SLOPE = Path(__file__).parent / "scenarios" / "standing_slope.toml"
INCLINE = Path(__file__).parent / "scenarios" / "incline_slope.toml"
ONLY = ["friction_standing", "friction_incline"]
TWIN = Path(sys.executable).parent / "twin"
FOOT_MU = [round(0.1 * i, 12) for i in range(1, 11)]


def twin(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(TWIN), "validate", *map(str, args)], capture_output=True, text=True, timeout=180
    )


def comparable(variants: list[dict]) -> list[dict]:
    """Sweep results without wall times (which differ from run to run)."""
    out = []
    for v in variants:
        checks = [{k: c[k] for k in c if k != "seconds"} for c in v["checks"]]
        out.append({"values": v["values"], "checks": checks, "limits": v["limits"]})
    return out


def test_foot_mu_sweep_fails_below_tan_theta_on_a_pool_and_on_ray(tmp_path):
    """Oracle: Coulomb. On a slope of θ (read from each scenario file) the held robot's feet, and
    each foot surface alone, stick iff μ ≥ tan θ (0.213 here), so μ 0.1, 0.2 fail and 0.3..1.0
    pass. The nearest grid values are 0.09 below and 0.09 above tan θ: at μ = 0.2 Coulomb
    predicts ½·g(sin θ − μ cos θ)·t² = 135 mm of slip in 1.5 s, at μ = 0.3 none (MuJoCo's soft
    friction creeps 2.6 mm, under the 5 mm threshold)."""
    for scenario in (SLOPE, INCLINE):
        assert load_scenario(scenario).world.incline_deg == load_scenario(SLOPE).world.incline_deg
    mu_critical = math.tan(math.radians(load_scenario(SLOPE).world.incline_deg))
    done = twin(
        HUMANOID, "--sweep", "foot_mu=0.1:1.0:10", "--scenario", SLOPE, "--scenario", INCLINE,
        "--only", ONLY[0], "--only", ONLY[1], "--jobs", "2", "--json",
        "--junit", tmp_path / "sweep.xml", "--markdown", tmp_path / "sweep.md",
        "--plots", tmp_path,
    )  # fmt: skip
    assert done.returncode == 1, done.stderr
    pool = json.loads(done.stdout)
    assert [v["values"]["foot_mu"] for v in pool["variants"]] == pytest.approx(FOOT_MU)
    for v in pool["variants"]:
        mu, checks = v["values"]["foot_mu"], {c["check"]: c for c in v["checks"]}
        assert sorted(checks) == sorted(ONLY)
        for check in checks.values():
            assert check["status"] == ("fail" if mu < mu_critical else "pass"), (mu, check)
        margin = v["limits"]["friction_standing"] - checks["friction_standing"]["value"]
        assert (margin < 0) == (mu < mu_critical), (mu, margin)  # what the plot draws
    # The reports: a JUnit case per variant × check, a matrix row per variant, the plot.
    cases = ET.parse(tmp_path / "sweep.xml").getroot().iter("testcase")
    failing = sorted(c.get("name") for c in cases if c.find("failure") is not None)
    assert failing == sorted(
        f"{check} ({scenario}) [foot_mu={m:g}]"
        for check, scenario in (
            ("friction_standing", "standing_slope"),
            ("friction_incline", "incline_slope"),
        )
        for m in (0.1, 0.2)
    )
    rows = [r for r in (tmp_path / "sweep.md").read_text().splitlines() if "foot_mu=" in r]
    assert [r.count("❌") for r in rows] == [2 * (m < mu_critical) for m in FOOT_MU]
    png = (tmp_path / "sweep_margins.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 10_000

    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, logging_level="ERROR")
    try:
        on_ray = sweep(
            [str(HUMANOID)],
            [parse_axis("foot_mu=0.1:1.0:10")],
            options={"scenarios": [str(SLOPE), str(INCLINE)], "only": ONLY},
            ray="auto",
        )
    finally:
        ray.shutdown()
    assert on_ray.executor.startswith("Ray cluster")
    ray_variants = [r.to_dict() for r in on_ray.runs]
    assert comparable(ray_variants) == comparable(pool["variants"])


def _model(values: dict[str, float], **args: str):
    robot = load_variant(str(HUMANOID), values, {"args": args})
    return robot.model


def test_variants_equal_the_gazebo_tags_they_stand_for():
    """Oracle: the file's own tag. foot_mu=0.3 gives the model that `foot_mu:=0.3` (the xacro
    argument that writes <mu1>/<mu2> into the feet's <gazebo> blocks) gives: same friction and
    min-μ priorities on every geom, to the bit. mass_scale=2 doubles every body's mass and
    inertia, and the kp → solref mapping sees the new masses (the humanoid sets no kp: SDF's
    rigid default, clamped to the stiffest stable S, which does not depend on mass).
    damping_scale=3 triples every joint's damping; friction_scale=0.5 halves every μ."""
    nominal = _model({})
    tagged = _model({}, foot_mu="0.3")
    swept = _model({"foot_mu": 0.3})
    assert not np.array_equal(nominal.geom_friction, swept.geom_friction)
    np.testing.assert_array_equal(swept.geom_friction, tagged.geom_friction)
    np.testing.assert_array_equal(swept.geom_priority, tagged.geom_priority)

    heavy = _model({"mass_scale": 2.0})
    np.testing.assert_allclose(heavy.body_mass, 2.0 * nominal.body_mass, rtol=1e-12)
    np.testing.assert_allclose(heavy.body_inertia, 2.0 * nominal.body_inertia, rtol=1e-9)

    damped = _model({"damping_scale": 3.0})
    np.testing.assert_allclose(damped.dof_damping, 3.0 * nominal.dof_damping, rtol=1e-12)
    assert nominal.dof_damping.max() > 0

    # kp_scale scales SDF's default kp 1e12 N/m to 1e4 N/m, soft enough to be reproduced, so
    # the mapping gives S = (1 - d)·kp/m on the 10 kg torso (d = SOFT_IMPEDANCE) instead of rigid.
    soft = _model({"kp_scale": 1e-8})
    body = soft.body("torso").id
    torso = [g for g in range(soft.ngeom) if soft.geom_bodyid[g] == body and soft.geom_contype[g]]
    stiffness = [-soft.geom_solref[g][0] for g in torso]
    mass = nominal.body("torso").mass[0]
    expected = (1 - SOFT_IMPEDANCE) * 1e4 / mass
    assert stiffness == pytest.approx([expected] * len(stiffness), rel=1e-9)
    assert all(nominal.geom_solref[g][0] != soft.geom_solref[g][0] for g in torso)

    slippery = _model({"friction_scale": 0.5})
    collide = nominal.geom_contype > 0
    np.testing.assert_allclose(
        slippery.geom_friction[collide, 0], 0.5 * nominal.geom_friction[collide, 0], rtol=1e-12
    )


def test_ground_mu_and_gravity_act_on_the_scenario_world():
    """ground_mu is the ground plane's μ: a 0.05 ground under the humanoid's μ=1 feet slides on
    the 12° slope (min rule: tan 12° = 0.21 > 0.05). gravity=1.62 on the `gravity` check: the
    free fall it measures follows ½gt² with the swept g (its oracle reads the world's g)."""
    options = {"scenarios": [str(SLOPE)], "only": ["friction_standing"]}
    slid = run_task(Task(str(HUMANOID), {"ground_mu": 0.05}, options)).results
    assert [r.status.value for r in slid] == ["fail"], slid
    drops = {}
    for g in (1.62, 9.81):
        (fall,) = run_task(Task(str(HUMANOID), {"gravity": g}, {"only": ["gravity"]})).results
        assert fall.status.value == "pass", fall
        number, unit = re.match(r"drop ([\d.e+-]+) (mm|m)\b", fall.measured).groups()
        drops[g] = float(number) * (1e-3 if unit == "mm" else 1.0)
    # ½gt² in the same time: the drops scale with g (to the check's own 1 % tolerance, twice).
    assert drops[1.62] / drops[9.81] == pytest.approx(1.62 / 9.81, rel=0.02), drops


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--sweep", "foot_muu=0.1:1:10"], "unknown parameter 'foot_muu'"),
        (["--sweep", "foot_mu=1.0:0.1:10"], "reversed range"),
        (["--sweep", "foot_mu=0.5:0.5:3"], "empty range"),
        (["--sweep", "foot_mu=0.1:1:0"], "give N ≥ 1"),
        (["--sweep", "foot_mu=0.1:1"], "NAME=LO:HI:N"),
        (["--sweep", "mass_scale=0:1:3"], "out of range"),
        (["--jobs", "0"], "--jobs 0"),
        (["--sweep", "foot_mu=0.1:1:2", "--ray", f"127.0.0.1:{_free_port()}"], "no Ray cluster"),
    ],
)
def test_bad_sweep_input_exits_2_with_one_message(args, needle):
    done = twin(HUMANOID, "--only", "inertial", *args)
    assert done.returncode == 2, (done.returncode, done.stdout, done.stderr)
    assert needle in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_axis_values_include_both_ends():
    assert parse_axis("foot_mu=0.1:1.0:10") == Axis("foot_mu", tuple(FOOT_MU))
    assert parse_axis("gravity=9.81:9.81:1").values == (9.81,)


def test_robot_that_does_not_convert_in_a_worker_exits_2_naming_it(tmp_path):
    missing = tmp_path / "nope.urdf"
    done = twin(missing, "--sweep", "foot_mu=0.1:1:2", "--only", "inertial", "--jobs", "1")
    assert done.returncode == 2, (done.stdout, done.stderr)
    assert str(missing) in done.stderr and "Traceback" not in done.stderr, done.stderr
