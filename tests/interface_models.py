"""Robots whose joints declare several command interfaces, in both tag forms.

`panda_arm()`: a 7-joint arm tagged as franka_description tags Franka's Panda for Gazebo
(gazebo:=true). The kinematics, joint limits and identified inertias are the Panda's, as
franka_description publishes them (inertias from Gaz et al.'s identification); the meshes are
left out, so the test needs no package. The tags are the ones that lose interfaces: three same-named
`<transmission>`s per arm joint (position, velocity, effort), franka_hw's state and model
transmissions that twin cannot drive, and `libgazebo_ros_control.so`.
"""

from __future__ import annotations

import math

# joint: (origin xyz, origin rpy, lower, upper [rad], velocity [rad/s], effort [N m])
PANDA_JOINTS = {
    "panda_joint1": ("0 0 0.333", "0 0 0", -2.8973, 2.8973, 2.175, 87.0),
    "panda_joint2": ("0 0 0", f"{-math.pi / 2} 0 0", -1.7628, 1.7628, 2.175, 87.0),
    "panda_joint3": ("0 -0.316 0", f"{math.pi / 2} 0 0", -2.8973, 2.8973, 2.175, 87.0),
    "panda_joint4": ("0.0825 0 0", f"{math.pi / 2} 0 0", -3.0718, -0.0698, 2.175, 87.0),
    "panda_joint5": ("-0.0825 0.384 0", f"{-math.pi / 2} 0 0", -2.8973, 2.8973, 2.61, 12.0),
    "panda_joint6": ("0 0 0", f"{math.pi / 2} 0 0", -0.0175, 3.7525, 2.61, 12.0),
    "panda_joint7": ("0.088 0 0", f"{math.pi / 2} 0 0", -2.8973, 2.8973, 2.61, 12.0),
}
# link: (mass [kg], com xyz [m], "ixx iyy izz ixy ixz iyz" [kg m²])
PANDA_LINKS = {
    "panda_link0": (
        0.629769,
        "-0.041018 -0.00014 0.049974",
        "3.15e-3 3.88e-3 4.285e-3 8.2904e-7 1.5e-4 8.2299e-6",
    ),
    "panda_link1": (
        4.970684,
        "0.003875 0.002081 -0.04762",
        "0.70337 0.70661 0.009117 -1.39e-4 6.772e-3 0.019169",
    ),
    "panda_link2": (
        0.646926,
        "-0.003141 -0.02872 0.003495",
        "7.962e-3 0.02811 0.025995 -3.925e-3 0.010254 7.04e-4",
    ),
    "panda_link3": (
        3.228604,
        "0.027518 0.039252 -0.066502",
        "0.037242 0.036155 0.01083 -4.761e-3 -0.011396 -0.012805",
    ),
    "panda_link4": (
        3.587895,
        "-0.05317 0.104419 0.027454",
        "0.025853 0.019552 0.028323 7.796e-3 -1.332e-3 8.641e-3",
    ),
    "panda_link5": (
        1.225946,
        "-0.011953 0.041065 -0.038437",
        "0.035549 0.029474 8.627e-3 -2.117e-3 -4.037e-3 2.29e-4",
    ),
    "panda_link6": (
        1.666555,
        "0.060149 -0.014117 -0.010517",
        "1.964e-3 4.354e-3 5.433e-3 1.09e-4 -1.158e-3 3.41e-4",
    ),
    "panda_link7": (
        0.735522,
        "0.010517 -0.004252 0.061597",
        "0.012516 0.010027 4.815e-3 -4.28e-4 -1.196e-3 -7.41e-4",
    ),
}
HARDWARE_INTERFACES = ("PositionJointInterface", "VelocityJointInterface", "EffortJointInterface")


def _link(name: str) -> str:
    mass, com, moments = PANDA_LINKS[name]
    ixx, iyy, izz, ixy, ixz, iyz = moments.split()
    return (
        f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="{ixy}" ixz="{ixz}" iyz="{iyz}"/>'
        f'</inertial><collision><geometry><sphere radius="0.04"/></geometry></collision></link>'
    )


def _joint(name: str, index: int) -> str:
    xyz, rpy, lower, upper, velocity, effort = PANDA_JOINTS[name]
    return (
        f'<joint name="{name}" type="revolute"><origin xyz="{xyz}" rpy="{rpy}"/>'
        f'<parent link="panda_link{index - 1}"/><child link="panda_link{index}"/>'
        f'<axis xyz="0 0 1"/><limit effort="{effort}" lower="{lower}" upper="{upper}" '
        f'velocity="{velocity}"/><dynamics damping="0.003" friction="0.0"/></joint>'
    )


def _transmission(joint: str, interface: str) -> str:
    hw = f"<hardwareInterface>hardware_interface/{interface}</hardwareInterface>"
    return (
        f'<transmission name="{joint}_transmission">'
        f"<type>transmission_interface/SimpleTransmission</type>"
        f'<joint name="{joint}">{hw}</joint><actuator name="{joint}_motor">{hw}</actuator>'
        f"</transmission>"
    )


def _franka_hw() -> str:
    state = "<hardwareInterface>franka_hw/FrankaStateInterface</hardwareInterface>"
    model = "<hardwareInterface>franka_hw/FrankaModelInterface</hardwareInterface>"
    joints = "".join(f'<joint name="{j}">{state}</joint>' for j in PANDA_JOINTS)
    return (
        f'<transmission name="panda_franka_state"><type>franka_hw/FrankaStateInterface</type>'
        f'{joints}<actuator name="panda_motor1">{state}</actuator></transmission>'
        f'<transmission name="panda_franka_model"><type>franka_hw/FrankaModelInterface</type>'
        f'<joint name="panda_joint1"><role>root</role>{model}</joint>'
        f'<joint name="panda_joint8"><role>tip</role>{model}</joint></transmission>'
    )


def panda_arm() -> str:
    """The Panda arm (no hand) fixed to `world`, every arm joint with three transmissions."""
    links = "".join(_link(name) for name in PANDA_LINKS)
    joints = "".join(_joint(name, i) for i, name in enumerate(PANDA_JOINTS, start=1))
    tags = "".join(_transmission(j, hw) for hw in HARDWARE_INTERFACES for j in PANDA_JOINTS)
    return f"""<robot name="panda">
  <link name="world"/>
  <joint name="world_joint" type="fixed"><parent link="world"/><child link="panda_link0"/></joint>
  {links}<link name="panda_link8"/>
  {joints}
  <joint name="panda_joint8" type="fixed"><origin xyz="0 0 0.107"/>
    <parent link="panda_link7"/><child link="panda_link8"/></joint>
  {tags}{_franka_hw()}
  <gazebo><plugin name="gazebo_ros_control" filename="libgazebo_ros_control.so">
    <controlPeriod>0.001</controlPeriod><robotSimType>franka_gazebo/FrankaHWSim</robotSimType>
  </plugin><self_collide>true</self_collide></gazebo>
</robot>
"""


def _disc(name: str) -> str:
    # a 1 kg disc of radius 0.1 m spinning about z: I = m r²/2 = 0.005 kg m²
    return (
        f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.003" iyy="0.003" '
        f'izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    )


# Three discs on vertical axes (no gravity load), fixed to `world`, effort 5 N m, 4 rad/s:
# d0 by <ros2_control> (position bounded to ±1, velocity) and a transmission (effort);
# d1 by one transmission only (position); d2 by one transmission naming two interfaces.
SEVERAL_INTERFACES = (
    '<robot name="discs"><link name="world"/>'
    '<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>'
    + _disc("base")
    + "".join(
        _disc(f"disc{i}") + f'<joint name="d{i}" type="revolute"><origin xyz="{0.3 * i} 0 0.1"/>'
        f'<parent link="base"/><child link="disc{i}"/><axis xyz="0 0 1"/>'
        f'<limit lower="-3" upper="3" effort="5" velocity="4"/></joint>'
        for i in range(3)
    )
    + """<ros2_control name="discs" type="system"><joint name="d0">
      <command_interface name="position"><param name="min">-1</param>
        <param name="max">1</param></command_interface>
      <command_interface name="velocity"/><state_interface name="position"/></joint>
    </ros2_control>"""
    + _transmission("d0", "EffortJointInterface")
    + _transmission("d1", "PositionJointInterface")
    + """<transmission name="d2_both"><type>transmission_interface/SimpleTransmission</type>
      <joint name="d2"><hardwareInterface>VelocityJointInterface</hardwareInterface>
      <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface></joint>
      <actuator name="d2_motor"/></transmission>
    <gazebo><plugin name="control" filename="libgazebo_ros2_control.so"/></gazebo></robot>"""
)
