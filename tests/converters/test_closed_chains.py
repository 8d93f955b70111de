"""Closed kinematic chains (SDF loops) close with equality constraints, as MuJoCo closes them.

A planar four-bar linkage (ground d, crank a, coupler b, rocker c; a + d <= b + c, so the
crank, the shortest bar, turns fully: Grashof crank-rocker) keeps one degree of freedom, and
its rocker follows the crank as the law of cosines says: the coupler's far pivot C lies on the
circle of radius b about the crank pin B and on the circle of radius c about the rocker's ground
pivot D. A parallelogram gripper finger stays parallel to the palm. The loop-closing joint
becomes two `connect` equalities, and the written scene.xml carries them.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters import convert
from converters.errors import ConversionError
from converters.mjcf.writer import write_model

# [m] bar lengths: crank a, coupler b, rocker c, ground d (0.1 + 0.4 <= 0.35 + 0.3).
A, B, C, D = 0.1, 0.35, 0.3, 0.4
THETA0 = math.pi / 2  # [rad] crank angle in the file
TOL_RAD = 1e-3  # [rad] rocker angle against the hand calculation
STEPS = 3000  # settling steps per crank angle (gravity off, damped)
INERTIAL = (
    "<inertial><mass>0.1</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz>"
    "<ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>"
)


def _link(name: str, x: float, y: float) -> str:
    return f'<link name="{name}"><pose>{x} {y} 0 0 0 0</pose>{INERTIAL}</link>'


def _joint(name: str, parent: str, child: str, x: float = 0.0, y: float = 0.0) -> str:
    return (
        f'<joint name="{name}" type="revolute"><pose>{x} {y} 0 0 0 0</pose>'
        f"<parent>{parent}</parent><child>{child}</child><axis><xyz>0 0 1</xyz></axis></joint>"
    )


def _coupler_pin(theta: float) -> tuple[float, float]:
    """C: the upper intersection of the circles |C - B| = b and |C - D| = c."""
    bx, by = A * math.cos(theta), A * math.sin(theta)
    dx, dy = D - bx, -by
    e = math.hypot(dx, dy)
    along = (B * B - C * C + e * e) / (2 * e)
    h = math.sqrt(B * B - along * along)
    mx, my = bx + along * dx / e, by + along * dy / e
    return mx - h * dy / e, my + h * dx / e


def _rocker_angle(theta: float) -> float:
    cx, cy = _coupler_pin(theta)
    return math.atan2(cy, cx - D)


def _four_bar(tmp_path: Path, closing: str | None = None) -> Path:
    bx, by = A * math.cos(THETA0), A * math.sin(THETA0)
    cx, cy = _coupler_pin(THETA0)
    loop = closing or _joint("close", "coupler", "rocker", cx - D, cy)
    body = (
        '<model name="fourbar">'
        + _link("ground", 0, 0)
        + _link("crank", 0, 0)
        + _link("coupler", bx, by)
        + _link("rocker", D, 0)
        + '<joint name="anchor" type="fixed"><parent>world</parent><child>ground</child></joint>'
        + _joint("crank_j", "ground", "crank")
        + _joint("coupler_j", "crank", "coupler")
        + _joint("rocker_j", "ground", "rocker")
        + loop
        + "</model>"
    )
    path = tmp_path / "fourbar.sdf"
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="1.8">\n{body}\n</sdf>\n')
    return path


def _mobility(model: mujoco.MjModel, data: mujoco.MjData) -> int:
    """Degrees of freedom left by the equality constraints at the current pose."""
    mujoco.mj_forward(model, data)
    rows = data.efc_J[: data.ne * model.nv].reshape(data.ne, model.nv) if data.ne else None
    rank = 0 if rows is None else np.linalg.matrix_rank(rows, tol=1e-9)
    return model.nv - int(rank)


def _hold(model: mujoco.MjModel, data: mujoco.MjData, joint: str, angle: float) -> None:
    """Hold `joint` at `angle` [rad] (qpos0-relative) and let the others settle."""
    adr = model.joint(joint).qposadr[0]
    dof = model.joint(joint).dofadr[0]
    for _ in range(STEPS):
        data.qpos[adr] = angle
        data.qvel[dof] = 0.0
        mujoco.mj_step(model, data)


def _settled(path: Path) -> tuple[mujoco.MjModel, mujoco.MjData]:
    spec, _ = convert(path)
    model = spec.compile()
    model.opt.gravity[:] = 0.0
    model.dof_damping[:] = 0.05
    return model, mujoco.MjData(model)


def _assert_rocker_follows_the_crank(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """A full turn of the crank in 30° steps, each from the previous pose (same branch): the
    rocker within TOL_RAD of the law of cosines."""
    phi0 = _rocker_angle(THETA0)
    for step in range(1, 13):
        theta = THETA0 + math.radians(30 * step)
        _hold(model, data, "crank_j", theta - THETA0)
        measured = phi0 + data.qpos[model.joint("rocker_j").qposadr[0]]
        expected = _rocker_angle(theta)
        error = math.remainder(measured - expected, 2 * math.pi)
        assert abs(error) < TOL_RAD, (math.degrees(theta), measured, expected)


def test_four_bar_has_one_degree_of_freedom_and_follows_freudenstein(tmp_path: Path) -> None:
    model, data = _settled(_four_bar(tmp_path))
    assert (model.nv, model.neq) == (3, 2)
    assert all(t == mujoco.mjtEq.mjEQ_CONNECT for t in model.eq_type)
    assert _mobility(model, data) == 1
    _assert_rocker_follows_the_crank(model, data)


def test_parallel_gripper_finger_stays_parallel_with_one_degree_of_freedom(
    tmp_path: Path,
) -> None:
    # Palm with two bars of length L at x = 0 and x = S; the finger joins their tips.
    L, S = 0.08, 0.03
    body = (
        '<model name="gripper">'
        + _link("palm", 0, 0)
        + _link("bar1", 0, 0)
        + _link("bar2", S, 0)
        + _link("finger", 0, L)
        + '<joint name="anchor" type="fixed"><parent>world</parent><child>palm</child></joint>'
        + _joint("bar1_j", "palm", "bar1")
        + _joint("bar2_j", "palm", "bar2")
        + _joint("finger_j", "bar1", "finger")
        + _joint("close", "bar2", "finger", S, 0)
        + "</model>"
    )
    path = tmp_path / "gripper.sdf"
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="1.8">\n{body}\n</sdf>\n')
    model, data = _settled(path)
    assert _mobility(model, data) == 1
    finger = model.body("finger").id
    for angle in (-0.6, -0.3, 0.2, 0.5, 0.8):  # [rad] bar1 from upright
        _hold(model, data, "bar1_j", angle)
        bar2 = data.qpos[model.joint("bar2_j").qposadr[0]]
        assert abs(bar2 - angle) < TOL_RAD
        # The finger keeps its orientation: its x axis stays the palm's x axis.
        assert abs(math.atan2(data.xmat[finger][3], data.xmat[finger][0])) < TOL_RAD


def test_written_scene_carries_the_loop_equalities(tmp_path: Path) -> None:
    spec, report = convert(_four_bar(tmp_path))
    reference = spec.compile()
    write_model(spec, report, tmp_path / "out")
    scene = mujoco.MjModel.from_xml_path(str(tmp_path / "out" / "scene.xml"))
    assert scene.neq == reference.neq == 2
    np.testing.assert_allclose(scene.eq_type, reference.eq_type)
    # MJCF text keeps 6 significant digits: anchors agree within 1e-6 m.
    np.testing.assert_allclose(scene.eq_data[:, :3], reference.eq_data[:, :3], atol=1e-6)
    # The two anchors lie on the loop joint's axis (z), 0.1 m apart.
    anchors = reference.eq_data[:, :3]
    np.testing.assert_allclose(anchors[1] - anchors[0], [0, 0, 0.1], atol=1e-12)
    assert any("closes a loop" in entry.detail for entry in report.entries)


def test_prismatic_loop_joint_is_refused_naming_the_joint(tmp_path: Path) -> None:
    closing = (
        '<joint name="slide" type="prismatic"><parent>coupler</parent><child>rocker</child>'
        "<axis><xyz>1 0 0</xyz></axis></joint>"
    )
    with pytest.raises(ConversionError, match="joint 'slide'.*closes a loop"):
        convert(_four_bar(tmp_path, closing))


@pytest.mark.parametrize(
    ("kind", "eq_type", "mobility"),
    [
        # A weld closing the loop leaves the linkage rigid.
        ("fixed", mujoco.mjtEq.mjEQ_WELD, 0),
        # A ball at C leaves the planar crank-rocker its one degree of freedom.
        ("ball", mujoco.mjtEq.mjEQ_CONNECT, 1),
    ],
)
def test_fixed_and_ball_loop_joints(tmp_path: Path, kind: str, eq_type: int, mobility: int) -> None:
    cx, cy = _coupler_pin(THETA0)
    closing = (
        f'<joint name="close" type="{kind}"><pose>{cx - D} {cy} 0 0 0 0</pose>'
        "<parent>coupler</parent><child>rocker</child></joint>"
    )
    model, data = _settled(_four_bar(tmp_path, closing))
    assert list(model.eq_type) == [eq_type]
    assert _mobility(model, data) == mobility


def _urdf_link(name: str) -> str:
    return (
        f'<link name="{name}"><inertial><mass value="0.1"/>'
        '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    )


def _urdf_joint(name: str, kind: str, parent: str, child: str, x: float, y: float) -> str:
    return (
        f'<joint name="{name}" type="{kind}"><origin xyz="{x} {y} 0"/>'
        f'<parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/></joint>'
    )


def test_urdf_four_bar_closed_by_a_second_parent_follows_freudenstein(tmp_path: Path) -> None:
    """A URDF closes a loop as users write it for Gazebo: a joint into a link that already has
    a parent. A URDF joint turns about its child's origin, so the rocker carries a tip link
    (fixed, at the coupler pin C) that the closing joint takes as its child."""
    bx, by = A * math.cos(THETA0), A * math.sin(THETA0)
    cx, cy = _coupler_pin(THETA0)
    text = (
        '<robot name="fourbar">'
        + "".join(_urdf_link(n) for n in ("world", "ground", "crank", "coupler", "rocker", "tip"))
        + _urdf_joint("anchor", "fixed", "world", "ground", 0, 0)
        + _urdf_joint("crank_j", "continuous", "ground", "crank", 0, 0)
        + _urdf_joint("coupler_j", "continuous", "crank", "coupler", bx, by)
        + _urdf_joint("rocker_j", "continuous", "ground", "rocker", D, 0)
        + _urdf_joint("tip_j", "fixed", "rocker", "tip", cx - D, cy)
        + _urdf_joint("close", "continuous", "coupler", "tip", cx - bx, cy - by)
        + "</robot>"
    )
    path = tmp_path / "fourbar.urdf"
    path.write_text(text)
    model, data = _settled(path)
    assert (model.nv, model.neq) == (3, 2)
    assert _mobility(model, data) == 1
    _assert_rocker_follows_the_crank(model, data)


def test_urdf_second_parent_that_joins_nothing_else_is_refused_naming_both(tmp_path: Path) -> None:
    text = (
        '<robot name="r">'
        + "".join(_urdf_link(n) for n in "abc")
        + _urdf_joint("j1", "continuous", "a", "b", 0, 0)
        + _urdf_joint("j2", "continuous", "c", "b", 0, 0)
        + "</robot>"
    )
    path = tmp_path / "r.urdf"
    path.write_text(text)
    with pytest.raises(ConversionError, match="link 'b'.*two joints.*joint 'j2'"):
        convert(path)


def _triangle(tmp_path: Path, links: tuple[str, ...], extra: str) -> Path:
    """Links a, b, c joined a→b, a→c and b→c (the last closes the loop), plus `links`/`extra`."""
    text = (
        '<robot name="r">'
        + "".join(_urdf_link(n) for n in ("a", "b", "c", *links))
        + _urdf_joint("ab", "continuous", "a", "b", 0, 0)
        + _urdf_joint("ac", "continuous", "a", "c", 0.1, 0)
        + _urdf_joint("bc", "continuous", "b", "c", 0.1, 0)
        + extra
        + "</robot>"
    )
    path = tmp_path / "r.urdf"
    path.write_text(text)
    return path


def test_a_stray_link_beside_a_closed_loop_is_the_one_named(tmp_path: Path) -> None:
    with pytest.raises(ConversionError, match="links a, stray.*2 root links"):
        convert(_triangle(tmp_path, ("stray",), ""))


def test_a_command_interface_on_a_loop_joint_says_the_joint_closes_a_loop(tmp_path: Path) -> None:
    control = (
        '<ros2_control name="s" type="system"><joint name="bc">'
        '<command_interface name="position"/></joint></ros2_control>'
    )
    path = _triangle(
        tmp_path, ("world",), _urdf_joint("fix", "fixed", "world", "a", 0, 0) + control
    )
    with pytest.raises(ConversionError, match="joint 'bc', which closes a loop"):
        convert(path)
