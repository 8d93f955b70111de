"""The builder on small hand-written URDFs: joints, inertia, lumping, mimic, base, actuators."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters.mjcf.builder import ConvertOptions
from converters.pipeline import convert_full

INERTIAL = (
    '<inertial><origin xyz="{x} 0 0" rpy="{rpy}"/><mass value="{m}"/>'
    '<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="{ixy}" ixz="0" iyz="0"/></inertial>'
)


def _link(name: str, m: float = 1.0, x: float = 0.0, rpy: str = "0 0 0", ixy: float = 0.0) -> str:
    inertial = INERTIAL.format(x=x, rpy=rpy, m=m, ixx=0.02, iyy=0.03, izz=0.04, ixy=ixy)
    box = '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
    return f'<link name="{name}">{inertial}{box}</link>'


def _joint(name: str, kind: str, parent: str, child: str, extra: str = "", xyz: str = "0 0 0.5"):
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="0.1 0.2 0.3"/><axis xyz="0 1 0"/>{extra}</joint>'
    )


LIMIT = '<limit lower="-1" upper="1.5" effort="20" velocity="3"/>'


def _convert(tmp_path: Path, body: str, **options: bool) -> object:
    path = tmp_path / "robot.urdf"
    path.write_text(f'<robot name="t">{body}</robot>')
    return convert_full(path, options=ConvertOptions(**options))


def test_joint_types_map_to_hinge_slide_free_and_planar(tmp_path: Path) -> None:
    links = "".join(_link(n) for n in ("base", "a", "b", "c", "d"))
    joints = (
        _joint("rev", "revolute", "base", "a", LIMIT + '<dynamics damping="0.7" friction="0.2"/>')
        + _joint("cont", "continuous", "a", "b")
        + _joint("pri", "prismatic", "b", "c", LIMIT)
        + _joint("pla", "planar", "c", "d")
    )
    model = _convert(tmp_path, links + joints).spec.compile()
    types = {model.joint(i).name: int(model.jnt_type[i]) for i in range(model.njnt)}
    J = mujoco.mjtJoint
    assert types == {
        "floating_base": J.mjJNT_FREE,
        "rev": J.mjJNT_HINGE,
        "cont": J.mjJNT_HINGE,
        "pri": J.mjJNT_SLIDE,
        "pla_x": J.mjJNT_SLIDE,
        "pla_y": J.mjJNT_SLIDE,
        "pla_yaw": J.mjJNT_HINGE,
    }, "MuJoCo joint types"
    rev = model.joint("rev")
    assert rev.range.tolist() == [-1.0, 1.5] and bool(rev.limited[0]), "revolute range [rad]"
    assert not bool(model.joint("cont").limited[0]), "continuous must be unlimited"
    assert model.dof_damping[rev.dofadr[0]] == pytest.approx(0.7), "damping [N·m·s/rad]"
    assert model.dof_frictionloss[rev.dofadr[0]] == pytest.approx(0.2), "frictionloss [N·m]"
    assert model.actuator("rev").ctrlrange.tolist() == [-20.0, 20.0], "ctrlrange = ±effort"
    assert model.actuator("rev").forcerange.tolist() == [-20.0, 20.0], "forcerange = ±effort"
    assert np.allclose(model.jnt_axis[rev.id], [0, 1, 0]), "axis in the child frame"


def test_full_inertia_with_origin_rpy_keeps_off_diagonal_terms(tmp_path: Path) -> None:
    body = _link("base", m=2.0, x=0.1, rpy="0.3 -0.2 0.9", ixy=0.005)
    model = _convert(tmp_path, body).spec.compile()
    roll, pitch, yaw = 0.3, -0.2, 0.9
    cr, sr, cp, sp, cy, sy = (
        np.cos(roll),
        np.sin(roll),
        np.cos(pitch),
        np.sin(pitch),
        np.cos(yaw),
        np.sin(yaw),
    )
    R = (
        np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
        @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
        @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    )
    expected = R @ np.array([[0.02, 0.005, 0], [0.005, 0.03, 0], [0, 0, 0.04]]) @ R.T
    iquat = model.body_iquat[1]
    Q = np.zeros(9)
    mujoco.mju_quat2Mat(Q, iquat)
    Q = Q.reshape(3, 3)
    actual = Q @ np.diag(model.body_inertia[1]) @ Q.T
    assert np.abs(actual - expected).max() < 1e-12, "inertia tensor in the link frame [kg·m²]"
    assert model.body_ipos[1].tolist() == pytest.approx([0.1, 0, 0]), "COM [m]"
    assert model.body_mass[1] == pytest.approx(2.0), "mass [kg]"


def test_fixed_joint_is_lumped_with_mass_merged_and_a_site_kept(tmp_path: Path) -> None:
    body = _link("base", m=1.0) + _link("tool", m=3.0) + _joint("f", "fixed", "base", "tool")
    done = _convert(tmp_path, body)
    model = done.spec.compile()
    assert model.nbody == 2, "the fixed child must not be a body"
    assert model.body("base").mass[0] == pytest.approx(4.0), "merged mass [kg]"
    assert model.body("base").ipos.tolist() == pytest.approx([0, 0, 0.375]), "merged COM [m]"
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    assert data.site("tool").xpos.tolist() == pytest.approx([0, 0, 0.5]), "lumped link site [m]"
    assert done.provenance.body_of_link["tool"] == "base", "provenance of the lumped link"
    kept = _convert(tmp_path, body, keep_fixed=True).spec.compile()
    assert kept.nbody == 3 and kept.njnt == 1, "--keep-fixed keeps a welded body, no joint"


def test_fixed_joint_to_world_anchors_the_base(tmp_path: Path) -> None:
    body = '<link name="world"/>' + _link("base") + _joint("anchor", "fixed", "world", "base")
    model = _convert(tmp_path, body).spec.compile()
    assert model.njnt == 0 and model.body("base").parentid[0] == 0, "base welded to world"


def test_moving_link_without_inertial_fails_and_repair_gives_it_mass(tmp_path: Path) -> None:
    from converters.errors import InertiaError

    body = (
        _link("base") + '<link name="arm"><collision><geometry><box size="0.1 0.2 0.3"/>'
        "</geometry></collision></link>" + _joint("j", "revolute", "base", "arm", LIMIT)
    )
    with pytest.raises(InertiaError, match="link 'arm'"):
        _convert(tmp_path, body)
    model = _convert(tmp_path, body, repair_inertia=True).spec.compile()
    assert model.body("arm").mass[0] == pytest.approx(1000 * 0.1 * 0.2 * 0.3), "box mass [kg]"


def test_mimic_with_negative_multiplier_and_offset_moves_the_follower_oppositely(
    tmp_path: Path,
) -> None:
    offset, multiplier = 0.3, -1.0
    mimic = f'<mimic joint="lead" multiplier="{multiplier}" offset="{offset}"/>'
    big = '<limit lower="-3" upper="3" effort="5" velocity="3"/>'
    body = (
        '<link name="world"/>'
        + _link("base")
        + _link("a")
        + _link("b")
        + _joint("anchor", "fixed", "world", "base")
        + _joint("lead", "revolute", "base", "a", big)
        + _joint("follow", "revolute", "base", "b", big + mimic, xyz="0.5 0 0")
    )
    done = _convert(tmp_path, body)
    model = done.spec.compile()
    model.opt.gravity[:] = 0
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("home").id)
    data.ctrl[model.actuator("lead").id] = 0.5
    mujoco.mj_step(model, data, 800)
    lead = data.joint("lead").qpos[0]
    follow = data.joint("follow").qpos[0]
    assert lead > 0.2, f"leader angle {lead:.3f} rad: the motor should have turned it"
    assert follow == pytest.approx(offset + multiplier * lead, abs=2e-3), (
        f"follower angle {follow:.4f} rad vs offset + multiplier · leader"
    )
    assert model.nu == 1, "the mimic follower gets no motor"


@pytest.mark.parametrize("suffix", ["stl", "obj", "ply", "glb", "dae"])
def test_mesh_formats_load_with_scale_into_the_spec(tmp_path: Path, suffix: str) -> None:
    import trimesh

    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(tmp_path / f"box.{suffix}")
    mesh = f'<geometry><mesh filename="box.{suffix}" scale="2 1 0.5"/></geometry>'
    body = _link("base").replace("</link>", f"<visual>{mesh}</visual></link>")
    body = body.replace(
        '<box size="0.1 0.1 0.1"/>', mesh.removeprefix("<geometry>").removesuffix("</geometry>")
    )
    model = _convert(tmp_path, body).spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for role in ("visual", "collision"):
        geom = model.geom(f"base_{role}_0")
        start, count = model.mesh_vertadr[geom.dataid[0]], model.mesh_vertnum[geom.dataid[0]]
        vertices = model.mesh_vert[start : start + count]
        extent = vertices.max(axis=0) - vertices.min(axis=0)
        assert np.sort(extent) == pytest.approx(np.sort([0.2, 0.2, 0.15]), abs=1e-6), (
            f"{suffix} {role}: scaled mesh extents [m]"
        )


def test_flat_mesh_is_kept_out_of_collision_and_reported(tmp_path: Path) -> None:
    from converters.mjcf.writer import stl_bytes
    from converters.report import Outcome

    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    (tmp_path / "flat.stl").write_bytes(stl_bytes(square, np.array([[0, 1, 2], [0, 2, 3]])))
    mesh = '<geometry><mesh filename="flat.stl"/></geometry>'
    body = _link("base").replace(
        "</link>", f"<visual>{mesh}</visual><collision>{mesh}</collision></link>"
    )
    done = _convert(tmp_path, body)
    model = done.spec.compile()
    names = {model.geom(i).name for i in range(model.ngeom)}
    assert "base_visual_0" in names and "base_collision_1" not in names, names
    flagged = [e for e in done.report.of(Outcome.APPROXIMATED) if "flat" in e.detail]
    assert flagged and "collision 1" in flagged[0].subject, done.report.entries


def test_gazebo_static_and_preserved_fixed_joint_shape_the_tree(tmp_path: Path) -> None:
    links = _link("base") + _link("tool") + _joint("f", "fixed", "base", "tool")
    gazebo = (
        "<gazebo><static>true</static></gazebo>"
        '<gazebo reference="f"><preserveFixedJoint>true</preserveFixedJoint></gazebo>'
    )
    model = _convert(tmp_path, links + gazebo).spec.compile()
    assert model.njnt == 0, "a static model has no free joint"
    assert model.nbody == 3, "a preserved fixed joint keeps its child as a body"


def test_mimic_of_an_unknown_joint_names_follower_and_leader(tmp_path: Path) -> None:
    from converters.errors import URDFStructureError

    mimic = '<mimic joint="nosuch" multiplier="1"/>'
    body = _link("base") + _link("a") + _joint("f", "revolute", "base", "a", LIMIT + mimic)
    with pytest.raises(URDFStructureError, match="joint 'f' <mimic joint='nosuch'>"):
        _convert(tmp_path, body)


def test_spherical_joint_becomes_a_ball(tmp_path: Path) -> None:
    body = _link("base") + _link("a") + _joint("s", "spherical", "base", "a")
    model = _convert(tmp_path, body).spec.compile()
    assert model.jnt_type[model.joint("s").id] == mujoco.mjtJoint.mjJNT_BALL, "joint type"
    assert model.nq == 7 + 4, "free joint + ball joint qpos width"


def test_visual_mesh_without_urdf_material_takes_the_files_colour(tmp_path: Path) -> None:
    import trimesh

    box = trimesh.creation.box(extents=(0.1, 0.1, 0.1))
    box.visual.face_colors = [255, 0, 0, 255]
    box.export(tmp_path / "red.glb")
    mesh = '<geometry><mesh filename="red.glb"/></geometry>'
    blue = '<material name="blue"><color rgba="0 0 1 1"/></material>'
    body = _link("base").replace(
        "</link>", f"<visual>{mesh}</visual><visual>{mesh}{blue}</visual></link>"
    )
    model = _convert(tmp_path, body).spec.compile()
    assert model.geom("base_visual_0").rgba.tolist() == pytest.approx([1, 0, 0, 1]), "file colour"
    assert model.geom("base_visual_1").rgba.tolist() == pytest.approx([0, 0, 1, 1]), "URDF wins"
