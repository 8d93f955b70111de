"""One robot written as URDF (with `<gazebo>` tags) and as SDF converts to the same MuJoCo model.

Every feature the two formats share: poses and joint frames, a full inertia tensor with a
rotated inertial frame, revolute and prismatic joints with limits, efforts, damping and
friction, a kept fixed joint, box/cylinder/sphere shapes, Gazebo friction and kp/kd.
"""

from __future__ import annotations

import numpy as np
import pytest

from converters import convert
from converters.gazebo.contact import SOFT_IMPEDANCE

INERTIA = "ixx='0.02' iyy='0.03' izz='0.04' ixy='0.001' ixz='-0.002' iyz='0.0015'"
URDF = f"""<robot name="twin_arm">
  <link name="base">
    <inertial><origin xyz="0.01 0.02 -0.01" rpy="0.1 0.2 0.3"/><mass value="2"/>
      <inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
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
    <inertial><mass value="0.1"/>
      <inertia ixx="0.00001" iyy="0.00001" izz="0.00001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="arm"/><origin xyz="0.1 0 0.05" rpy="0 0 0.3"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1.2" effort="5" velocity="2"/>
    <dynamics damping="0.1" friction="0.05"/>
  </joint>
  <joint name="slide" type="prismatic">
    <parent link="arm"/><child link="slider"/><origin xyz="0 0 0.4"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="0.1" effort="20" velocity="0.5"/>
  </joint>
  <joint name="tip_joint" type="fixed">
    <parent link="slider"/><child link="tip"/><origin xyz="0 0 0.05"/>
  </joint>
  <gazebo reference="tip_joint"><preserveFixedJoint>true</preserveFixedJoint></gazebo>
  <gazebo reference="arm"><mu1>0.4</mu1><mu2>0.4</mu2><kp>1e5</kp><kd>10</kd></gazebo>
</robot>
"""

SURFACE = (
    "<surface><friction><ode><mu>0.4</mu><mu2>0.4</mu2></ode></friction>"
    "<contact><ode><kp>1e5</kp><kd>10</kd></ode></contact></surface>"
)
SDF = f"""<sdf version="1.8"><model name="twin_arm">
  <link name="base">
    <inertial><pose>0.01 0.02 -0.01 0.1 0.2 0.3</pose><mass>2</mass><inertia>
      <ixx>0.02</ixx><iyy>0.03</iyy><izz>0.04</izz><ixy>0.001</ixy><ixz>-0.002</ixz>
      <iyz>0.0015</iyz></inertia></inertial>
    <collision name="c"><geometry><box><size>0.3 0.2 0.1</size></box></geometry></collision>
  </link>
  <link name="arm"><pose relative_to="base">0.1 0 0.05 0 0 0.3</pose>
    <inertial><pose>0 0 0.2 0 0 0</pose><mass>0.8</mass><inertia>
      <ixx>0.011</ixx><iyy>0.011</iyy><izz>0.0004</izz></inertia></inertial>
    <collision name="c"><pose>0 0 0.2 0 0 0</pose>
      <geometry><cylinder><radius>0.03</radius><length>0.4</length></cylinder></geometry>
      {SURFACE}</collision>
  </link>
  <link name="slider"><pose relative_to="arm">0 0 0.4 0 0 0</pose>
    <inertial><mass>0.3</mass><inertia>
      <ixx>0.0002</ixx><iyy>0.0002</iyy><izz>0.0002</izz></inertia></inertial>
    <collision name="c"><geometry><sphere><radius>0.04</radius></sphere></geometry></collision>
  </link>
  <link name="tip"><pose relative_to="slider">0 0 0.05 0 0 0</pose>
    <inertial><mass>0.1</mass><inertia>
      <ixx>0.00001</ixx><iyy>0.00001</iyy><izz>0.00001</izz></inertia></inertial>
  </link>
  <joint name="shoulder" type="revolute"><parent>base</parent><child>arm</child>
    <axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1.2</upper><effort>5</effort>
      <velocity>2</velocity></limit><dynamics><damping>0.1</damping>
      <friction>0.05</friction></dynamics></axis></joint>
  <joint name="slide" type="prismatic"><parent>arm</parent><child>slider</child>
    <axis><xyz>0 0 1</xyz><limit><lower>0</lower><upper>0.1</upper><effort>20</effort>
      <velocity>0.5</velocity></limit></axis></joint>
  <joint name="tip_joint" type="fixed"><parent>slider</parent><child>tip</child></joint>
</model></sdf>
"""

FIELDS = {
    "body_mass": 1e-12,
    "body_inertia": 1e-12,
    "body_ipos": 1e-12,
    "body_pos": 1e-12,
    "body_quat": 1e-12,
    "jnt_type": 0,
    "jnt_range": 1e-12,
    "jnt_axis": 1e-12,
    "jnt_pos": 1e-12,
    "dof_damping": 1e-12,
    "dof_frictionloss": 1e-12,
    "geom_type": 0,
    "geom_size": 1e-12,
    "geom_pos": 1e-12,
    "geom_friction": 1e-12,
    "geom_priority": 0,
    "geom_solref": 1e-9,
    "geom_solimp": 1e-12,
    "actuator_ctrlrange": 1e-12,
}


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    root = tmp_path_factory.mktemp("equivalence")
    (root / "arm.urdf").write_text(URDF)
    (root / "arm.sdf").write_text(SDF)
    return convert(root / "arm.urdf")[0].compile(), convert(root / "arm.sdf")[0].compile()


def _names(model, kind: str, count: int) -> list[str]:
    return [getattr(model, kind)(i).name for i in range(count)]


def test_same_bodies_joints_and_geoms(models) -> None:
    urdf, sdf = models
    assert _names(urdf, "body", urdf.nbody) == _names(sdf, "body", sdf.nbody), "bodies"
    assert _names(urdf, "joint", urdf.njnt) == _names(sdf, "joint", sdf.njnt), "joints"
    assert _names(urdf, "geom", urdf.ngeom) == _names(sdf, "geom", sdf.ngeom), "geoms"
    assert _names(urdf, "actuator", urdf.nu) == _names(sdf, "actuator", sdf.nu), "motors"


@pytest.mark.parametrize("field", sorted(FIELDS))
def test_same_physics(models, field: str) -> None:
    urdf, sdf = models
    expected, actual = np.asarray(getattr(urdf, field)), np.asarray(getattr(sdf, field))
    assert actual.shape == expected.shape, f"{field}: shapes {actual.shape} vs {expected.shape}"
    assert actual == pytest.approx(expected, abs=FIELDS[field] or 0), field


def test_principal_axes_agree_up_to_sign(models) -> None:
    urdf, sdf = models
    for body in range(1, urdf.nbody):
        q1, q2 = urdf.body_iquat[body], sdf.body_iquat[body]
        assert abs(float(np.dot(q1, q2))) == pytest.approx(1.0, abs=1e-9), urdf.body(body).name


def test_gazebo_values_reach_the_arm(models) -> None:
    _, sdf = models
    arm = sdf.geom("arm_collision_0")
    assert arm.friction[0] == pytest.approx(0.4), "μ from <surface>"
    assert -arm.solref[0] == pytest.approx((1 - SOFT_IMPEDANCE) * 1e5 / 0.8, rel=1e-9), "S"
