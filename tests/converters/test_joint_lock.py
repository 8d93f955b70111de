"""A revolute or prismatic joint whose lower limit equals its upper limit is locked there.

Gazebo cannot move such a joint (ODE and DART hold it at the value). The converted MuJoCo joint
keeps its name and must hold the value under load: a 1 kg link cantilevered 0.5 m from the
joint, under gravity, for 2 s of simulated time, from the `home` keyframe. A free hinge or
slide with that load moves by tenths of a radian or metre in that time, so the bound of 1e-6
separates locked from unlocked by five orders of magnitude.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters.pipeline import convert_full

HOLD_TOL = 1e-6  # [rad or m] largest drift of a locked joint over the run
DURATION_S = 2.0  # [s] simulated time
ARM_M = 0.5  # [m] the link's centre of mass from the joint axis
INERTIA = 'ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"'
# Horizontal hinge (gravity turns it); vertical slide (gravity pulls along it).
AXES = {"revolute": "0 1 0", "prismatic": "0 0 1"}
MJ_TYPE = {"revolute": mujoco.mjtJoint.mjJNT_HINGE, "prismatic": mujoco.mjtJoint.mjJNT_SLIDE}
CASES = [(kind, value) for kind in AXES for value in (0.0, 0.7)]


def _urdf(tmp_path: Path, kind: str, value: float) -> Path:
    path = tmp_path / "lock.urdf"
    path.write_text(
        '<robot name="r"><link name="world"/>'
        f'<link name="base"><inertial><mass value="5"/><inertia {INERTIA}/></inertial></link>'
        '<joint name="pin" type="fixed"><parent link="world"/><child link="base"/>'
        '<origin xyz="0 0 1"/></joint>'
        f'<link name="arm"><inertial><origin xyz="{ARM_M} 0 0"/><mass value="1"/>'
        f"<inertia {INERTIA}/></inertial></link>"
        f'<joint name="lock" type="{kind}"><parent link="base"/><child link="arm"/>'
        f'<axis xyz="{AXES[kind]}"/>'
        f'<limit lower="{value}" upper="{value}" effort="10" velocity="1"/></joint></robot>'
    )
    return path


def _sdf(tmp_path: Path, kind: str, value: float) -> Path:
    inertia = "<ixx>0.001</ixx><iyy>0.001</iyy><izz>0.001</izz>"
    path = tmp_path / "lock.sdf"
    path.write_text(
        '<?xml version="1.0"?><sdf version="1.8"><model name="r">'
        '<link name="base"><pose>0 0 1 0 0 0</pose><inertial><mass>5</mass>'
        f"<inertia>{inertia}</inertia></inertial></link>"
        '<joint name="pin" type="fixed"><parent>world</parent><child>base</child></joint>'
        '<link name="arm"><pose>0 0 1 0 0 0</pose>'
        f"<inertial><pose>{ARM_M} 0 0 0 0 0</pose><mass>1</mass>"
        f"<inertia>{inertia}</inertia></inertial></link>"
        f'<joint name="lock" type="{kind}"><parent>base</parent><child>arm</child>'
        f"<axis><xyz>{AXES[kind]}</xyz><limit><lower>{value}</lower><upper>{value}</upper>"
        "</limit></axis></joint></model></sdf>"
    )
    return path


WRITERS = {"urdf": _urdf, "sdf": _sdf}


def _largest_drift(model: mujoco.MjModel, value: float) -> float:
    """Largest |q - value| [rad or m] of joint `lock` over the run, from the home keyframe."""
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    address = model.jnt_qposadr[model.joint("lock").id]
    drift = abs(data.qpos[address] - value)
    while data.time < DURATION_S:
        mujoco.mj_step(model, data)
        drift = max(drift, abs(data.qpos[address] - value))
    return float(drift)


@pytest.mark.parametrize("fmt", sorted(WRITERS))
@pytest.mark.parametrize(("kind", "value"), CASES)
def test_equal_limits_lock_the_joint_at_their_value(
    tmp_path: Path, fmt: str, kind: str, value: float
) -> None:
    conversion = convert_full(WRITERS[fmt](tmp_path, kind, value))
    model = conversion.spec.compile()
    assert int(model.joint("lock").type[0]) == int(MJ_TYPE[kind]), "the joint keeps its name"
    drift = _largest_drift(model, value)
    assert drift < HOLD_TOL, f"{fmt} {kind} locked at {value}: drifted {drift:.3g}"
    details = [e.detail for e in conversion.report.entries if "'lock'" in e.subject]
    assert any("(lower = upper), as Gazebo does" in d for d in details), details


@pytest.mark.parametrize("fmt", sorted(WRITERS))
def test_an_unlocked_joint_still_moves(tmp_path: Path, fmt: str) -> None:
    """The same hinge with lower < upper swings under gravity: the load is a real one."""
    path = WRITERS[fmt](tmp_path, "revolute", 0.0)
    text = path.read_text().replace('lower="0.0" upper="0.0"', 'lower="-1" upper="1"')
    path.write_text(text.replace("<upper>0.0</upper>", "<upper>1</upper>"))
    model = convert_full(path).spec.compile()
    assert _largest_drift(model, 0.0) > 0.1, "an unlocked hinge under a 4.9 N m load"
    assert np.isfinite(model.jnt_range).all()


@pytest.mark.parametrize("limit", ["", "<limit/>", "<limit><effort>-1</effort></limit>"])
def test_sdf_axis_without_limits_takes_sdf_defaults(tmp_path: Path, limit: str) -> None:
    """SDFormat's defaults: lower -1e16, upper 1e16 (unlimited), effort and velocity -1 (none)."""
    path = _sdf(tmp_path, "revolute", 0.0)
    text = path.read_text().replace("<limit><lower>0.0</lower><upper>0.0</upper></limit>", limit)
    path.write_text(text)
    model = convert_full(path).spec.compile()
    joint = model.joint("lock")
    assert not model.jnt_limited[joint.id], "no position limits"
    driven = [i for i in range(model.nu) if model.actuator_trnid[i, 0] == joint.id]
    assert all(not model.actuator_forcelimited[i] for i in driven), "no effort bound"
    assert _largest_drift(model, 0.0) > 0.1, "the hinge swings freely"
    details = [e.detail for e in convert_full(path).report.entries if "'lock'" in e.subject]
    assert not any("limit" in d for d in details), f"SDF's defaults are not a problem: {details}"


def _urdf_limit(tmp_path: Path, limit: str) -> Path:
    path = _urdf(tmp_path, "revolute", 0.0)
    path.write_text(
        path.read_text().replace('<limit lower="0.0" upper="0.0" effort="10" velocity="1"/>', limit)
    )
    return path


def test_a_urdf_limit_without_lower_and_upper_holds_the_joint_at_0(tmp_path: Path) -> None:
    """ROS's URDF parser, which Gazebo reads URDF through, takes a missing bound as 0: the
    joint is held at 0 under the 4.9 N m load, and the report says why and what to write."""
    conversion = convert_full(_urdf_limit(tmp_path, '<limit effort="10" velocity="1"/>'))
    drift = _largest_drift(conversion.spec.compile(), 0.0)
    assert drift < HOLD_TOL, f"drifted {drift:.3g} rad"
    details = " ".join(e.detail for e in conversion.report.entries if "'lock'" in e.subject)
    for part in ("no lower and upper", "[0, 0] rad", 'type="continuous"', "lower = upper"):
        assert part in details, f"{part!r} not in {details!r}"


@pytest.mark.parametrize(
    ("bounds", "expected"), [('lower="-1"', (-1.0, 0.0)), ('upper="0.5"', (0.0, 0.5))]
)
def test_a_urdf_limit_with_one_bound_takes_0_for_the_other(
    tmp_path: Path, bounds: str, expected: tuple[float, float]
) -> None:
    """The hinge swings under gravity within the range URDF's default makes, never past it."""
    path = _urdf_limit(tmp_path, f'<limit {bounds} effort="10" velocity="1"/>')
    conversion = convert_full(path)
    model = conversion.spec.compile()
    joint = model.joint("lock")
    assert model.jnt_limited[joint.id] and tuple(model.jnt_range[joint.id]) == expected
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    seen = []
    while data.time < DURATION_S:
        mujoco.mj_step(model, data)
        seen.append(float(data.qpos[model.jnt_qposadr[joint.id]]))
    low, high = expected
    assert low - 0.02 < min(seen) and max(seen) < high + 0.02, (min(seen), max(seen))
    details = " ".join(e.detail for e in conversion.report.entries if "'lock'" in e.subject)
    missing = "upper" if "lower" in bounds else "lower"
    assert f"has no {missing}: URDF reads a missing bound as 0" in details, details


def test_a_urdf_revolute_joint_without_limit_is_unlimited_and_named(tmp_path: Path) -> None:
    """ROS's parser refuses such a file; twin loads it unlimited and says what to add."""
    conversion = convert_full(_urdf_limit(tmp_path, ""))
    model = conversion.spec.compile()
    assert not model.jnt_limited[model.joint("lock").id]
    assert _largest_drift(model, 0.0) > 0.1, "the hinge swings freely"
    warnings = [
        e.detail
        for e in conversion.report.entries
        if "'lock'" in e.subject and e.outcome.value == "warning"
    ]
    assert any("without <limit>: URDF requires one" in w for w in warnings), warnings
    assert not any("None" in w for w in warnings), warnings
