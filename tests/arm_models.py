"""Arms for the servo and `--fixed-base` tests.

`floating_arm` [m, kg]: without a `world` link, as vendors ship arms: a 2 kg base box
0.2 × 0.2 × 0.1 m, and above it (0.1 m up) a 0.5 m horizontal link on hinge 'shoulder' about y,
which gravity swings down. `bob_arm`: one hinge fixed to the world, its mass at one point.
"""

from __future__ import annotations

INERTIA = 'ixx="0.001" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"'  # [kg m^2]


def floating_arm(link_mass: float = 1.0, world_link: bool = False) -> str:
    """The arm as URDF, with a link of `link_mass` [kg]; `world_link` adds a `world` link and
    a fixed joint to `base_link` (how Gazebo users fix it by hand)."""
    world = (
        '<link name="world"/><joint name="world_joint" type="fixed">'
        '<parent link="world"/><child link="base_link"/></joint>'
        if world_link
        else ""
    )
    return f"""<robot name="arm">{world}
  <link name="base_link">
    <inertial><mass value="2"/><inertia {INERTIA}/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0.25 0 0"/><mass value="{link_mass}"/><inertia {INERTIA}/></inertial>
    <collision><origin xyz="0.25 0 0" rpy="0 1.5707963 0"/>
      <geometry><cylinder radius="0.03" length="0.5"/></geometry></collision>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base_link"/><child link="upper"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="100" velocity="2"/></joint>
</robot>"""


def panda_like_arm(world_link: bool = True) -> str:
    """A Panda-like 7-joint arm (`interface_models`' kinematics, masses and limits: effort
    87/87/87/87/12/12/12 N m, velocity 2.175-2.61 rad/s) whose joints ros2_control commands by
    position alone; `world_link` fixes it to a `world` link, otherwise it floats (`--fixed-base`
    welds it)."""
    from interface_models import PANDA_JOINTS, PANDA_LINKS, _joint, _link

    world = (
        '<link name="world"/><joint name="world_joint" type="fixed">'
        '<parent link="world"/><child link="panda_link0"/></joint>'
        if world_link
        else ""
    )
    links = "".join(_link(name) for name in PANDA_LINKS)
    joints = "".join(_joint(name, i) for i, name in enumerate(PANDA_JOINTS, start=1))
    interfaces = "".join(
        f'<joint name="{j}"><command_interface name="position"/>'
        f'<state_interface name="position"/></joint>'
        for j in PANDA_JOINTS
    )
    return f"""<robot name="panda_like">{world}{links}{joints}
  <ros2_control name="arm" type="system"><hardware><plugin>x</plugin></hardware>{interfaces}
  </ros2_control>
  <gazebo><plugin name="control" filename="libgazebo_ros2_control.so"/></gazebo></robot>"""


def bob_arm(effort: float, mass: float = 1.0, reach: float = 0.2) -> str:
    """`mass` [kg] `reach` [m] out on hinge 'j' about y (±3 rad, `effort` [N m], 1 rad/s), on a
    1 kg base fixed to a `world` link: a load m·g·reach·cos q at the hinge."""
    return f"""<robot name="a"><link name="world"/>
<link name="base"><inertial><mass value="1"/>
  <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="arm"><inertial><origin xyz="{reach} 0 0"/><mass value="{mass}"/>
  <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
  <limit lower="-3" upper="3" effort="{effort}" velocity="1"/></joint></robot>"""
