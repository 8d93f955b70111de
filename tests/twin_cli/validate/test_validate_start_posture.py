"""`twin validate` from an invalid start posture names the posture, not twin: an arm whose zero
pose folds its forearm into its base (self-collision on), or a model whose `home` key puts a
joint outside its range, fails `initial_overlap`, and the physics checks that would measure
that push are not run, saying why; from a valid posture (`-J`) the same arm passes them."""

from __future__ import annotations

import pytest
from models import write_urdf

from twin_cli.validate import validate
from twin_cli.validate.checks.base import Status

DEPENDENT = ["tracking", "stability", "zero_gravity"]


def _box(mass: float, half: tuple[float, float, float], z: float) -> str:
    x, y, h = half
    ixx = mass * ((2 * y) ** 2 + (2 * h) ** 2) / 12
    izz = mass * ((2 * x) ** 2 + (2 * y) ** 2) / 12
    size = f"{2 * x} {2 * y} {2 * h}"
    return (
        f'<inertial><origin xyz="0 0 {z}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{ixx}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<collision><origin xyz="0 0 {z}"/><geometry><box size="{size}"/></geometry></collision>'
        f'<visual><origin xyz="0 0 {z}"/><geometry><box size="{size}"/></geometry></visual>'
    )


FOLDING_ARM = f"""<robot name="folding_arm">
<link name="world"/>
<link name="base">{_box(2.0, (0.05, 0.05, 0.05), 0.0)}</link>
<link name="upper">{_box(0.5, (0.02, 0.02, 0.15), 0.15)}</link>
<link name="forearm">{_box(0.3, (0.02, 0.02, 0.15), -0.25)}</link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/>
  <origin xyz="0 0 0.5"/></joint>
<joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
  <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
  <limit lower="-1.5" upper="1.5" effort="30" velocity="2"/></joint>
<joint name="elbow" type="revolute"><parent link="upper"/><child link="forearm"/>
  <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
  <limit lower="-0.5" upper="2.5" effort="10" velocity="2"/></joint>
<gazebo reference="forearm"><self_collide>true</self_collide></gazebo>
</robot>"""


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    return write_urdf(tmp_path_factory.mktemp("folding"), FOLDING_ARM, "folding_arm.urdf")


def _by_check(run) -> dict:
    return {r.check: r for r in run.results}


def test_an_invalid_start_posture_fails_initial_overlap_and_holds_back_its_dependents(arm):
    run = validate(arm, only=["initial_overlap", *DEPENDENT])
    results = _by_check(run)
    overlap = results["initial_overlap"]
    assert overlap.status is Status.FAIL, overlap
    hints = " ".join(overlap.hints)
    assert "'base' and 'forearm' overlap" in hints, overlap.hints
    for name in DEPENDENT:
        held = results[name]
        assert held.status is Status.NOT_APPLICABLE, (name, held.status, held.measured)
        assert "not run because of initial_overlap" in held.details[0], held.details
        assert "'base' and 'forearm' overlap" in held.details[0], held.details
    said = [h for r in run.results for h in (*r.hints, *r.details)]
    assert not [h for h in said if "twin bug" in h], "the posture, not twin, is to blame"
    assert run.exit_code == 1, "a failed check, not a crash"


def test_from_a_valid_posture_the_same_arm_passes(arm):
    run = validate(arm, only=["initial_overlap", *DEPENDENT], joints={"elbow": 1.5})
    results = _by_check(run)
    assert results["initial_overlap"].status is Status.PASS, results["initial_overlap"]
    for name in DEPENDENT:
        ran = results[name]
        assert ran.status in (Status.PASS, Status.WARN), (name, ran.measured, ran.hints)
    assert run.passed, [(r.check, r.status, r.hints) for r in run.results]


OUTSIDE = """<mujoco model="outside"><compiler angle="radian"/><worldbody>
  <body name="base" pos="0 0 0.5"><geom type="box" size="0.05 0.05 0.05" mass="2"/>
  <body name="link" pos="0 0 0.05"><joint name="hinge" axis="0 1 0" range="0.6 2.5"/>
    <geom type="capsule" fromto="0 0 0.05 0 0 0.3" size="0.02" mass="0.5"/></body></body>
  </worldbody>
  <actuator><motor name="hinge" joint="hinge" ctrlrange="-10 10"/></actuator>
  <keyframe><key name="home" qpos="0"/></keyframe></mujoco>"""


def test_a_home_key_outside_a_joints_range_fails_and_holds_back_its_dependents(tmp_path):
    path = tmp_path / "outside.xml"
    path.write_text(OUTSIDE, encoding="utf-8")
    run = validate(path, only=["initial_overlap", "stability"])
    results = _by_check(run)
    overlap = results["initial_overlap"]
    assert overlap.status is Status.FAIL, overlap
    assert any("joint 'hinge' starts at 0" in h and "-J hinge=" in h for h in overlap.hints)
    held = results["stability"]
    assert held.status is Status.NOT_APPLICABLE, (held.status, held.measured)
    assert "outside its range [0.6, 2.5]" in held.details[0], held.details


def test_without_initial_overlap_in_the_run_a_held_check_fails(arm):
    """`--only stability` from the folding pose: nothing else would fail the run, so the held
    check does, with the same reason (never a pass on a check that did not run)."""
    run = validate(arm, only=["stability"])
    (held,) = run.results
    assert held.status is Status.FAIL, (held.status, held.measured)
    assert "not run because of initial_overlap" in held.hints[0], held.hints
    assert run.exit_code == 1
