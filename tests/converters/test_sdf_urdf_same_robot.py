"""One robot written as URDF (with `<gazebo>` tags) and as SDF converts to the same MuJoCo model.

The robot has what both formats share: a base with a full inertia tensor in a rotated inertial
frame, a revolute joint with a rotated origin, limits, effort, velocity, damping and friction,
a prismatic joint, a fixed joint to a small tip, box/cylinder/sphere collisions, Gazebo
friction (mu1/mu2) and contact stiffness (kp/kd). The SDF is written three ways: link poses
relative_to the parent link (1.7), URDF-style joint frames with child links relative_to their
joint (1.7, the pose-frame-semantics proposal's "parity with URDF"), and model-frame link poses
composed here by hand (1.6).

URDF joint frames sit at the child link's origin, so an SDF joint with no `<pose>` (relative to
its child) is the same joint. Gazebo lumps a URDF fixed joint's child into its parent (unless
`preserveFixedJoint`), while an SDF fixed joint keeps two links; against the lumped URDF the
SDF's slider+tip are compared as one rigid body (mass, centre of mass, inertia about it).
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from converters import convert
from converters.report import Outcome

RTOL = 1e-12  # relative, every compared quantity
ATOL = 1e-12  # absolute floor for entries that are 0 in one model and ~1e-17 in the other

# --- the robot ------------------------------------------------------------------------------
SHOULDER_ORIGIN = (0.1, 0.0, 0.05, 0.3, -0.2, 0.5)  # x y z roll pitch yaw, base → arm
SLIDE_ORIGIN = (0.0, 0.0, 0.4, 0.0, 0.0, 0.0)  # arm → slider
TIP_ORIGIN = (0.0, 0.0, 0.05, 0.0, 0.4, 0.0)  # slider → tip (fixed)

URDF = """<robot name="arm">
  <link name="base">
    <inertial><origin xyz="0.01 0.02 -0.01" rpy="0.1 0.2 0.3"/><mass value="2"/>
      <inertia ixx="0.02" iyy="0.03" izz="0.04" ixy="0.001" ixz="-0.002" iyz="0.0015"/>
    </inertial>
    <collision><origin xyz="0 0 0.05" rpy="0 0 0.2"/>
      <geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.2"/><mass value="0.8"/>
      <inertia ixx="0.011" iyy="0.011" izz="0.0004" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.2"/>
      <geometry><cylinder radius="0.03" length="0.4"/></geometry></collision>
  </link>
  <link name="slider">
    <inertial><mass value="0.3"/>
      <inertia ixx="0.0002" iyy="0.0002" izz="0.0002" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.04"/></geometry></collision>
  </link>
  <link name="tip">
    <inertial><origin xyz="0.01 0 0"/><mass value="0.1"/>
      <inertia ixx="0.00001" iyy="0.00002" izz="0.00003" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.02 0.02 0.02"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0.1 0 0.05" rpy="0.3 -0.2 0.5"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1.2" effort="5" velocity="2"/>
    <dynamics damping="0.1" friction="0.05"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="arm"/><child link="slider"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.1" effort="20" velocity="0.5"/>
    <dynamics damping="0.3" friction="0"/>
  </joint>
  <joint name="tip_joint" type="fixed">
    <parent link="slider"/><child link="tip"/><origin xyz="0 0 0.05" rpy="0 0.4 0"/>
  </joint>
  <gazebo reference="arm"><mu1>0.4</mu1><mu2>0.3</mu2><kp>1e5</kp><kd>10</kd></gazebo>
  <gazebo reference="tip"><mu1>0.7</mu1><mu2>0.7</mu2></gazebo>
  {preserve}
</robot>
"""
PRESERVE = "<gazebo reference='tip_joint'><preserveFixedJoint>true</preserveFixedJoint></gazebo>"

ARM_SURFACE = (
    "<surface><friction><ode><mu>0.4</mu><mu2>0.3</mu2></ode></friction>"
    "<contact><ode><kp>1e5</kp><kd>10</kd></ode></contact></surface>"
)
TIP_SURFACE = "<surface><friction><ode><mu>0.7</mu><mu2>0.7</mu2></ode></friction></surface>"


def _links(arm_pose: str, slider_pose: str, tip_pose: str) -> str:
    return f"""
  <link name="base">
    <inertial><pose>0.01 0.02 -0.01 0.1 0.2 0.3</pose><mass>2</mass><inertia>
      <ixx>0.02</ixx><iyy>0.03</iyy><izz>0.04</izz><ixy>0.001</ixy><ixz>-0.002</ixz>
      <iyz>0.0015</iyz></inertia></inertial>
    <collision name="box"><pose>0 0 0.05 0 0 0.2</pose>
      <geometry><box><size>0.3 0.2 0.1</size></box></geometry></collision>
  </link>
  <link name="arm">{arm_pose}
    <inertial><pose>0 0 0.2 0 0 0</pose><mass>0.8</mass><inertia>
      <ixx>0.011</ixx><iyy>0.011</iyy><izz>0.0004</izz></inertia></inertial>
    <collision name="cylinder"><pose>0 0 0.2 0 0 0</pose>
      <geometry><cylinder><radius>0.03</radius><length>0.4</length></cylinder></geometry>
      {ARM_SURFACE}</collision>
  </link>
  <link name="slider">{slider_pose}
    <inertial><mass>0.3</mass><inertia>
      <ixx>0.0002</ixx><iyy>0.0002</iyy><izz>0.0002</izz></inertia></inertial>
    <collision name="sphere"><geometry><sphere><radius>0.04</radius></sphere></geometry>
    </collision>
  </link>
  <link name="tip">{tip_pose}
    <inertial><pose>0.01 0 0 0 0 0</pose><mass>0.1</mass><inertia>
      <ixx>0.00001</ixx><iyy>0.00002</iyy><izz>0.00003</izz></inertia></inertial>
    <collision name="cube"><geometry><box><size>0.02 0.02 0.02</size></box></geometry>
      {TIP_SURFACE}</collision>
  </link>"""


def _joints(shoulder_pose: str = "", slide_pose: str = "", tip_pose: str = "") -> str:
    return f"""
  <joint name="shoulder" type="revolute">{shoulder_pose}<parent>base</parent><child>arm</child>
    <axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1.2</upper><effort>5</effort>
      <velocity>2</velocity></limit>
      <dynamics><damping>0.1</damping><friction>0.05</friction></dynamics></axis></joint>
  <joint name="slide" type="prismatic">{slide_pose}<parent>arm</parent><child>slider</child>
    <axis><xyz>0 0 1</xyz><limit><lower>0</lower><upper>0.1</upper><effort>20</effort>
      <velocity>0.5</velocity></limit>
      <dynamics><damping>0.3</damping><friction>0</friction></dynamics></axis></joint>
  <joint name="tip_joint" type="fixed">{tip_pose}<parent>slider</parent><child>tip</child>
  </joint>"""


def _pose_text(values: tuple[float, ...]) -> str:
    return " ".join(repr(float(v)) for v in values)


def _sdf(version: str, links: str, joints: str) -> str:
    return f'<sdf version="{version}"><model name="arm">{links}{joints}\n</model></sdf>\n'


# 1.7: each link posed from its parent link with the URDF joint origin.
SDF_LINK_RELATIVE = _sdf(
    "1.7",
    _links(
        f'<pose relative_to="base">{_pose_text(SHOULDER_ORIGIN)}</pose>',
        f'<pose relative_to="arm">{_pose_text(SLIDE_ORIGIN)}</pose>',
        f'<pose relative_to="slider">{_pose_text(TIP_ORIGIN)}</pose>',
    ),
    _joints(),
)
# 1.7: the proposal's parity with URDF: joints posed from the parent, children from the joint.
SDF_JOINT_RELATIVE = _sdf(
    "1.7",
    _links(
        '<pose relative_to="shoulder"/>',
        '<pose relative_to="slide"/>',
        '<pose relative_to="tip_joint"/>',
    ),
    _joints(
        f'<pose relative_to="base">{_pose_text(SHOULDER_ORIGIN)}</pose>',
        f'<pose relative_to="arm">{_pose_text(SLIDE_ORIGIN)}</pose>',
        f'<pose relative_to="slider">{_pose_text(TIP_ORIGIN)}</pose>',
    ),
)


def _X(x: float, y: float, z: float, roll: float, pitch: float, yaw: float) -> np.ndarray:
    """x y z roll pitch yaw → 4×4 with R = Rz(yaw)·Ry(pitch)·Rx(roll)."""
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    T = np.eye(4)
    T[:3, :3] = Rz @ Ry @ Rx
    T[:3, 3] = (x, y, z)
    return T


def _model_frame_pose(T: np.ndarray) -> str:
    R = T[:3, :3]
    rpy = (math.atan2(R[2, 1], R[2, 2]), math.asin(-R[2, 0]), math.atan2(R[1, 0], R[0, 0]))
    return f"<pose>{_pose_text((*T[:3, 3], *rpy))}</pose>"


# 1.6: link poses in the model frame, composed as URDF does: X_M_arm = X_base_arm (base at M),
# X_M_slider = X_M_arm·X_arm_slider, X_M_tip = X_M_slider·X_slider_tip.
X_M_ARM = _X(*SHOULDER_ORIGIN)
X_M_SLIDER = X_M_ARM @ _X(*SLIDE_ORIGIN)
X_M_TIP = X_M_SLIDER @ _X(*TIP_ORIGIN)
SDF_MODEL_FRAME = _sdf(
    "1.6",
    _links(_model_frame_pose(X_M_ARM), _model_frame_pose(X_M_SLIDER), _model_frame_pose(X_M_TIP)),
    _joints(),
)
SDF_VARIANTS = {
    "link-relative_to": SDF_LINK_RELATIVE,
    "joint-relative_to": SDF_JOINT_RELATIVE,
    "1.6-model-frame": SDF_MODEL_FRAME,
}


# --- conversion -----------------------------------------------------------------------------
class Converted:
    """A compiled model at qpos0 with its kinematics, and the conversion report."""

    def __init__(self, path: Path) -> None:
        spec, self.report = convert(path)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        mujoco.mj_kinematics(self.model, self.data)
        mujoco.mj_comPos(self.model, self.data)

    def names(self, kind: str, count: int) -> list[str]:
        return [getattr(self.model, kind)(i).name for i in range(count)]


@pytest.fixture(scope="module")
def root(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("same_robot")


@pytest.fixture(scope="module")
def urdf_lumped(root: Path) -> Converted:
    path = root / "arm_lumped.urdf"
    path.write_text(URDF.format(preserve=""))
    return Converted(path)


@pytest.fixture(scope="module")
def urdf_preserved(root: Path) -> Converted:
    path = root / "arm_preserved.urdf"
    path.write_text(URDF.format(preserve=PRESERVE))
    return Converted(path)


@pytest.fixture(scope="module", params=sorted(SDF_VARIANTS))
def sdf(request, root: Path) -> Converted:
    path = root / f"arm_{request.param}.sdf"
    path.write_text(SDF_VARIANTS[request.param])
    return Converted(path)


def assert_same(actual, expected, what: str) -> None:
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} vs {expected.shape}"
    np.testing.assert_allclose(actual, expected, rtol=RTOL, atol=ATOL, err_msg=what)


# --- bodies ---------------------------------------------------------------------------------
KEPT_BODIES = ("world", "base", "arm")  # neither lumped nor holding a lumped link


def test_bodies_are_the_links_and_urdf_lumps_the_fixed_tip(urdf_lumped, urdf_preserved, sdf):
    assert urdf_lumped.names("body", urdf_lumped.model.nbody) == [
        "world",
        "base",
        "arm",
        "slider",
    ], "URDF: tip lumped into slider"
    expected = urdf_preserved.names("body", urdf_preserved.model.nbody)
    assert sdf.names("body", sdf.model.nbody) == expected, "SDF keeps the fixed joint's tip"


@pytest.mark.parametrize("body", KEPT_BODIES)
def test_kept_bodies_have_the_same_inertia_and_pose(urdf_lumped, sdf, body: str) -> None:
    u, s = urdf_lumped, sdf
    bu, bs = u.model.body(body).id, s.model.body(body).id
    assert_same(s.model.body_mass[bs], u.model.body_mass[bu], f"{body}: body_mass [kg]")
    assert_same(s.model.body_inertia[bs], u.model.body_inertia[bu], f"{body}: body_inertia [kg m²]")
    assert_same(s.model.body_ipos[bs], u.model.body_ipos[bu], f"{body}: body_ipos [m]")
    assert_same(s.data.xpos[bs], u.data.xpos[bu], f"{body}: xpos at qpos0 [m]")
    assert_same(s.data.xmat[bs], u.data.xmat[bu], f"{body}: xmat at qpos0")
    # Principal axes: a quaternion and its negative are the same rotation.
    qu, qs = u.model.body_iquat[bu], s.model.body_iquat[bs]
    assert_same(np.sign(qs @ qu) * qs, qu, f"{body}: body_iquat (up to sign)")


def _rigid_body(c: Converted, bodies: tuple[str, ...]) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass [kg], centre of mass [m] and inertia about it [kg m²] of `bodies` as one, in world."""
    ids = [c.model.body(b).id for b in bodies]
    masses = c.model.body_mass[ids]
    mass = float(masses.sum())
    com = (masses[:, None] * c.data.xipos[ids]).sum(axis=0) / mass
    inertia = np.zeros((3, 3))
    for b, m in zip(ids, masses, strict=True):
        R = c.data.ximat[b].reshape(3, 3)
        r = c.data.xipos[b] - com
        # Rotate the principal inertia to world, then move it to the common centre (Steiner).
        inertia += R @ np.diag(c.model.body_inertia[b]) @ R.T + m * (
            r @ r * np.eye(3) - np.outer(r, r)
        )
    return mass, com, inertia


def test_lumped_slider_is_the_sdf_slider_and_tip_as_one_body(urdf_lumped, sdf) -> None:
    mass_u, com_u, inertia_u = _rigid_body(urdf_lumped, ("slider",))
    mass_s, com_s, inertia_s = _rigid_body(sdf, ("slider", "tip"))
    assert_same(mass_s, mass_u, "slider+tip: mass [kg]")
    assert_same(com_s, com_u, "slider+tip: centre of mass at qpos0 [m]")
    assert_same(inertia_s, inertia_u, "slider+tip: inertia about the COM, world [kg m²]")
    assert_same(
        sdf.data.xpos[sdf.model.body("slider").id],
        urdf_lumped.data.xpos[urdf_lumped.model.body("slider").id],
        "slider: xpos at qpos0 [m]",
    )


def test_total_mass_is_the_same(urdf_lumped, sdf) -> None:
    assert_same(sdf.model.body_mass.sum(), urdf_lumped.model.body_mass.sum(), "total mass [kg]")
    # 2 + 0.8 + 0.3 + 0.1 kg.
    assert_same(sdf.model.body_mass.sum(), 3.2, "total mass, as written [kg]")


def test_tip_frame_is_where_urdf_lumped_it(urdf_lumped, sdf) -> None:
    # URDF keeps a lumped link's frame as a site; the SDF tip is its own body there.
    site = urdf_lumped.model.site("tip").id
    tip = sdf.model.body("tip").id
    assert_same(sdf.data.xpos[tip], urdf_lumped.data.site_xpos[site], "tip origin [m]")
    assert_same(sdf.data.xmat[tip], urdf_lumped.data.site_xmat[site], "tip orientation")
    # By hand: X_M_tip = X_base_arm·X_arm_slider·X_slider_tip.
    assert_same(sdf.data.xpos[tip], X_M_TIP[:3, 3], "tip origin, composed by hand [m]")


def test_with_preserved_fixed_joint_every_body_is_the_same(urdf_preserved, sdf) -> None:
    u, s = urdf_preserved, sdf
    for field in ("body_mass", "body_inertia", "body_ipos", "body_pos", "body_quat"):
        assert_same(getattr(s.model, field), getattr(u.model, field), f"all bodies: {field}")
    assert_same(s.data.xpos, u.data.xpos, "all bodies: xpos at qpos0 [m]")
    signs = np.sign(np.sum(s.model.body_iquat * u.model.body_iquat, axis=1))
    assert_same(signs[:, None] * s.model.body_iquat, u.model.body_iquat, "body_iquat (±)")


# --- joints and actuators -------------------------------------------------------------------
JOINT_FIELDS = ("jnt_type", "jnt_limited", "jnt_range", "jnt_solref", "jnt_solimp", "qpos0")
DOF_FIELDS = ("dof_damping", "dof_frictionloss", "dof_armature")
ACTUATOR_FIELDS = ("actuator_ctrlrange", "actuator_forcerange", "actuator_gear", "jnt_actfrcrange")


def test_same_joints_ranges_damping_friction_and_motors(urdf_lumped, sdf) -> None:
    u, s = urdf_lumped, sdf
    assert s.names("joint", s.model.njnt) == u.names("joint", u.model.njnt), "joint names"
    assert s.names("actuator", s.model.nu) == u.names("actuator", u.model.nu), "motor names"
    for field in JOINT_FIELDS + DOF_FIELDS + ACTUATOR_FIELDS:
        assert_same(getattr(s.model, field), getattr(u.model, field), field)
    assert_same(s.data.xanchor, u.data.xanchor, "joint anchors at qpos0 [m]")
    assert_same(s.data.xaxis, u.data.xaxis, "joint axes at qpos0")
    # As written: shoulder [-1, 1.2] rad, damping 0.1 N m s, friction 0.05 N m; slide [0, 0.1] m.
    shoulder, slide = s.model.joint("shoulder"), s.model.joint("slide")
    assert_same(shoulder.range, [-1.0, 1.2], "shoulder range [rad]")
    assert_same(slide.range, [0.0, 0.1], "slide range [m]")
    assert_same(s.model.dof_damping[shoulder.dofadr[0]], 0.1, "shoulder damping")
    assert_same(s.model.dof_frictionloss[shoulder.dofadr[0]], 0.05, "shoulder frictionloss")
    assert_same(s.model.dof_damping[slide.dofadr[0]], 0.3, "slide damping")


def test_shoulder_axis_is_y_of_the_rotated_joint_frame(sdf) -> None:
    # URDF and SDF both put the axis in the joint (= child) frame: R_M_arm·(0, 1, 0).
    joint = sdf.model.joint("shoulder").id
    assert_same(sdf.data.xaxis[joint], X_M_ARM[:3, 1], "shoulder axis, composed by hand")
    assert_same(sdf.data.xanchor[joint], X_M_ARM[:3, 3], "shoulder anchor, by hand [m]")


# --- geoms ------------------------------------------------------------------------------------
GEOM_FIELDS = (
    "geom_type",
    "geom_size",
    "geom_friction",
    "geom_priority",
    "geom_solref",
    "geom_solimp",
    "geom_solmix",
    "geom_condim",
    "geom_margin",
    "geom_gap",
    "geom_contype",
    "geom_conaffinity",
    "geom_rbound",
)


def test_same_geoms_shapes_friction_and_contact(urdf_lumped, sdf) -> None:
    u, s = urdf_lumped, sdf
    assert s.names("geom", s.model.ngeom) == u.names("geom", u.model.ngeom), "geom names"
    for field in GEOM_FIELDS:
        assert_same(getattr(s.model, field), getattr(u.model, field), field)
    # Where each geom is in the world (the tip's cube hangs on slider in URDF, on tip in SDF).
    assert_same(s.data.geom_xpos, u.data.geom_xpos, "geom_xpos at qpos0 [m]")
    assert_same(s.data.geom_xmat, u.data.geom_xmat, "geom_xmat at qpos0")


def test_gazebo_friction_and_stiffness_reach_the_right_geoms(sdf) -> None:
    m = sdf.model
    friction = {m.geom(g).name: m.geom_friction[g][0] for g in range(m.ngeom)}
    # mu 0.4 on the arm, 0.7 on the tip, Gazebo's default 1 elsewhere.
    assert_same(friction["arm_collision_0"], 0.4, "arm μ")
    assert_same(friction["tip_collision_0"], 0.7, "tip μ")
    assert_same(friction["base_collision_0"], 1.0, "base μ (Gazebo default)")
    # kp/kd on the arm only: its solref differs from the default geoms'.
    arm, base = m.geom("arm_collision_0").id, m.geom("base_collision_0").id
    assert not np.allclose(m.geom_solref[arm], m.geom_solref[base]), "arm kp/kd → its own solref"


def test_same_approximations_are_reported(urdf_lumped, sdf) -> None:
    # What MuJoCo cannot do (μ2 ≠ μ1, kd raised, velocity limits) is reported for both files.
    def tags(c: Converted) -> set[tuple[str, str | None]]:
        found = c.report.of(Outcome.APPROXIMATED) + c.report.of(Outcome.IGNORED)
        return {(e.outcome.value, e.tag) for e in found}

    missing, extra = tags(urdf_lumped) - tags(sdf), tags(sdf) - tags(urdf_lumped)
    assert not missing and not extra, (
        f"(outcome, tag) of approximated/ignored entries: SDF lacks {sorted(missing, key=str)}, "
        f"adds {sorted(extra, key=str)}"
    )
