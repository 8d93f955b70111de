"""Mobile bases the drive tests write: one per kinematic family, URDF and SDF, with the plugin
given as XML (and a two-joint arm for joint trajectory controllers). Every base's root link
origin is the kinematic model's reference point (the fixed axle's midpoint), so its world pose
is what the model predicts.

Geometry [m, kg]: wheels of radius R on continuous joints about their y axis (a positive speed
rolls forward), a chassis box above them; steering joints turn about z (positive: left).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from twin_cli.world import World

R = 0.05  # wheel radius [m]
TRACK = 0.30  # left-right wheel spacing [m]
WHEEL_BASE = 0.40  # fixed axle to steered axle [m]
WIDTH = 0.004  # wheel width [m] (the drive tests also run 3 cm wheels)
SKID_A = 0.06  # half the wheel base of skid_steer_bot's default layout [m] (a/c = 0.4)
COULOMB_FACTOR = 1.0 / (1.0 + (SKID_A / (TRACK / 2)) ** 2)
"""A skid steer's turn rate over its command under Coulomb friction, its wheels at the unicycle's
speeds and equal loads: 1/(1 + (a/c)²) = 0.862 for skid_steer_bot's default layout."""
COULOMB_SHORT = 0.05
"""Most a skid steer of skid_steer_bot's default layout turns below Coulomb's rate, as a fraction
of it. Measured for commands of 0.3-1 rad/s with 0-0.3 m/s and each skid-steer plugin the tests
use, as the mean over half a turn of heading: 0.01 % to 4.2 % below (ROS 2's diff drive, whose
wheels ramp at 1 rad/s², the most)."""
COULOMB_OVER = 0.01
"""Most a skid steer turns above Coulomb's rate, as a fraction of it: the rate is that of rigid
contacts, and MuJoCo's soft friction rows give a little at the wheels (measured up to 0.7 %; a
heading loop that steered on the world's heading turned 16 % above)."""


def _inertial(mass: float, i: float, xyz: str = "0 0 0") -> str:
    return (
        f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/><inertia ixx="{i}" iyy="{i}" '
        f'izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _wheel(name: str, width: float = WIDTH) -> str:
    return (
        f'<link name="{name}">{_inertial(0.3, 4e-4)}<collision><origin rpy="1.5708 0 0"/>'
        f'<geometry><cylinder radius="{R}" length="{width}"/></geometry></collision></link>'
    )


def _continuous(name: str, parent: str, child: str, xyz: str) -> str:
    return (
        f'<joint name="{name}" type="continuous"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="0 1 0"/></joint>'
    )


def _steer(name: str, parent: str, child: str, xyz: str) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="0 0 1"/>'
        '<limit lower="-0.8" upper="0.8" effort="50" velocity="4"/></joint>'
    )


def _chassis(length: float, x: float, mass: float = 6.0) -> str:
    return (
        f'<link name="base_link">{_inertial(mass, 0.05, f"{x} 0 0.05")}<collision>'
        f'<origin xyz="{x} 0 0.06"/><geometry><box size="{length} 0.2 0.05"/></geometry>'
        "</collision></link>"
    )


def _caster(name: str, x: float) -> str:
    """A frictionless ball fixed under the chassis at `x` (keeps a two-wheeled base level)."""
    return (
        f'<link name="{name}">{_inertial(0.05, 1e-5)}<collision><geometry>'
        f'<sphere radius="{R}"/></geometry></collision></link>'
        f'<joint name="{name}_fix" type="fixed"><parent link="base_link"/>'
        f'<child link="{name}"/><origin xyz="{x} 0 0"/></joint>'
        f'<gazebo reference="{name}"><mu1>0</mu1><mu2>0</mu2></gazebo>'
    )


SKID_STEER_ROS1 = (  # gazebo_ros' ROS 1 skid steer on skid_steer_bot's wheels, 5 N m a wheel
    '<plugin name="skid" filename="libgazebo_ros_skid_steer_drive.so"><leftFrontJoint>'
    "left_front_joint</leftFrontJoint><rightFrontJoint>right_front_joint</rightFrontJoint>"
    "<leftRearJoint>left_rear_joint</leftRearJoint><rightRearJoint>right_rear_joint"
    "</rightRearJoint><wheelSeparation>0.3</wheelSeparation><wheelDiameter>0.1</wheelDiameter>"
    "<torque>5</torque></plugin>"
)


def skid_steer_bot(plugin: str, wheelbase: float = 0.12) -> str:
    """Four wheels `left_front_joint` ... `right_rear_joint`, `wheelbase` apart front to rear."""
    half = wheelbase / 2
    parts = [_chassis(0.3, 0.0)]
    for side, y in (("left", TRACK / 2), ("right", -TRACK / 2)):
        for end, x in (("front", half), ("rear", -half)):
            parts.append(_wheel(f"{side}_{end}"))
            parts.append(
                _continuous(f"{side}_{end}_joint", "base_link", f"{side}_{end}", f"{x} {y} 0")
            )
    return f'<robot name="skid">{"".join(parts)}<gazebo>{plugin}</gazebo></robot>'


ROS2_CONTROL = (  # gazebo_ros2_control with its controller manager's parameters beside the robot
    '<plugin filename="libgazebo_ros2_control.so" name="gazebo_ros2_control">'
    "<parameters>controllers.yaml</parameters></plugin>"
)


def with_ros2_control(robot: str, joints: tuple[str, ...]) -> str:
    """`robot` (a URDF) with a `<ros2_control>` block giving `joints` velocity commands."""
    interfaces = "".join(
        f'<joint name="{j}"><command_interface name="velocity"/><state_interface name="position"/>'
        '<state_interface name="velocity"/></joint>'
        for j in joints
    )
    block = (
        '<ros2_control name="GazeboSystem" type="system"><hardware><plugin>'
        f"gazebo_ros2_control/GazeboSystem</plugin></hardware>{interfaces}</ros2_control>"
    )
    return robot.replace("</robot>", f"{block}</robot>")


def with_diff_drive_controller(
    robot: str,
    left: tuple[str, ...],
    right: tuple[str, ...],
    folder: Path,
    multiplier: float = 1.0,
    rate: float = 100.0,
) -> str:
    """`robot` with velocity interfaces on its wheels, and the diff_drive_controller's
    controllers.yaml (`diff_drive_controller_yaml`) written in `folder` beside it."""
    (folder / "controllers.yaml").write_text(
        diff_drive_controller_yaml(left, right, multiplier, rate)
    )
    return with_ros2_control(robot, left + right)


def settled_base(folder: Path, robot: str, file_name: str = "base.urdf") -> World:
    """A world with `robot` written to `folder`/`file_name`, spawned on the ground as `base` and
    stepped 0.3 s so that it rests on its wheels."""
    from twin_cli.spawn_request import SpawnRequest
    from twin_cli.world import World

    path = folder / file_name
    path.write_text(robot)
    world = World()
    world.spawn(SpawnRequest(str(path), on_ground=True), name="base")
    world.step(300)
    return world


def diff_drive_controller_yaml(
    left: tuple[str, ...], right: tuple[str, ...], multiplier: float = 1.0, rate: float = 100.0
) -> str:
    """controllers.yaml: a diff_drive_controller on the wheels, TRACK apart, of radius R."""
    return f"""controller_manager:
  ros__parameters:
    update_rate: {rate:g}
    diff_cont:
      type: diff_drive_controller/DiffDriveController
diff_cont:
  ros__parameters:
    base_frame_id: base_link
    left_wheel_names: [{", ".join(left)}]
    right_wheel_names: [{", ".join(right)}]
    wheel_separation: {TRACK}
    wheel_separation_multiplier: {multiplier!r}
    wheel_radius: {R}
"""


def two_wheel_base(
    plugin: str,
    left: str = "wheel_left_joint",
    right: str = "wheel_right_joint",
    width: float = WIDTH,
) -> str:
    """Two driven wheels `width` [m] wide on the axle through the origin, frictionless casters
    fore and aft."""
    parts = [_chassis(0.3, 0.0), _caster("caster_front", 0.12), _caster("caster_rear", -0.12)]
    parts += [_wheel("wheel_left", width), _wheel("wheel_right", width)]
    parts.append(_continuous(left, "base_link", "wheel_left", f"0 {TRACK / 2} 0"))
    parts.append(_continuous(right, "base_link", "wheel_right", f"0 {-TRACK / 2} 0"))
    return f'<robot name="base">{"".join(parts)}<gazebo>{plugin}</gazebo></robot>'


def ackermann_car(plugin: str) -> str:
    """Rear wheels `rear_left_joint`/`rear_right_joint` on the origin's axle; front wheels
    `front_left_joint`/`front_right_joint` under steering joints `left_steering_joint`/
    `right_steering_joint`, WHEEL_BASE ahead."""
    parts = [_chassis(0.5, WHEEL_BASE / 2)]
    for side, y in (("left", TRACK / 2), ("right", -TRACK / 2)):
        parts.append(_wheel(f"rear_{side}"))
        parts.append(_continuous(f"rear_{side}_joint", "base_link", f"rear_{side}", f"0 {y} 0"))
        parts.append(f'<link name="{side}_knuckle">{_inertial(0.1, 1e-4)}</link>')
        parts.append(
            _steer(f"{side}_steering_joint", "base_link", f"{side}_knuckle", f"{WHEEL_BASE} {y} 0")
        )
        parts.append(_wheel(f"front_{side}"))
        parts.append(
            _continuous(f"front_{side}_joint", f"{side}_knuckle", f"front_{side}", "0 0 0")
        )
    return f'<robot name="car">{"".join(parts)}<gazebo>{plugin}</gazebo></robot>'


def tricycle(plugin: str) -> str:
    """Encoder wheels `left_wheel_joint`/`right_wheel_joint` on the origin's axle; the front wheel
    `front_wheel_joint` under `front_steering_joint`, WHEEL_BASE ahead."""
    parts = [_chassis(0.5, WHEEL_BASE / 2)]
    for side, y in (("left", TRACK / 2), ("right", -TRACK / 2)):
        parts.append(_wheel(f"{side}_wheel"))
        parts.append(_continuous(f"{side}_wheel_joint", "base_link", f"{side}_wheel", f"0 {y} 0"))
    parts.append(f'<link name="fork">{_inertial(0.1, 1e-4)}</link>')
    parts.append(_steer("front_steering_joint", "base_link", "fork", f"{WHEEL_BASE} 0 0"))
    parts.append(_wheel("front_wheel"))
    parts.append(_continuous("front_wheel_joint", "fork", "front_wheel", "0 0 0"))
    return f'<robot name="trike">{"".join(parts)}<gazebo>{plugin}</gazebo></robot>'


def planar_base(plugin: str) -> str:
    """A box on four balls (μ = 0.5) with no wheels: driven only by its planar move plugin."""
    feet = "".join(
        f'<collision><origin xyz="{x} {y} 0"/><geometry><sphere radius="{R}"/></geometry>'
        "</collision>"
        for x in (-0.15, 0.15)
        for y in (-0.1, 0.1)
    )
    base = f'<link name="base_link">{_inertial(8.0, 0.1, "0 0 0.05")}{feet}</link>'
    tags = '<gazebo reference="base_link"><mu1>0.5</mu1><mu2>0.5</mu2></gazebo>'
    return f'<robot name="mover">{base}{tags}<gazebo>{plugin}</gazebo></robot>'


def _sdf_wheel(name: str, parent: str, xyz: str) -> str:
    return (
        f'<link name="{name}"><pose relative_to="{name}_joint"/><inertial><mass>0.3</mass>'
        "<inertia><ixx>4e-4</ixx><iyy>4e-4</iyy><izz>4e-4</izz></inertia></inertial>"
        f'<collision name="c"><pose>0 0 0 1.5708 0 0</pose><geometry><cylinder><radius>{R}'
        f"</radius><length>{WIDTH}</length></cylinder></geometry></collision></link>"
        f'<joint name="{name}_joint" type="revolute"><pose relative_to="{parent}">{xyz} 0 0 0'
        f"</pose><parent>{parent}</parent><child>{name}</child><axis><xyz>0 1 0</xyz><limit>"
        "<lower>-1e16</lower><upper>1e16</upper></limit></axis></joint>"
    )


def _sdf_chassis(x: float, length: float = 0.5, name: str = "base_link") -> str:
    return (
        f'<link name="{name}"><inertial><pose>{x} 0 0.05 0 0 0</pose><mass>6</mass><inertia>'
        "<ixx>0.05</ixx><iyy>0.05</iyy><izz>0.05</izz></inertia></inertial>"
        f'<collision name="body"><pose>{x} 0 0.06 0 0 0</pose><geometry><box><size>{length} 0.2 '
        "0.05</size></box></geometry></collision></link>"
    )


def sdf_diff_drive(plugin: str, model: str = "dd", base: str = "base_link") -> str:
    """`two_wheel_base` as an SDF model named `model`: wheels `wheel_left_joint`/
    `wheel_right_joint` on the origin's axle, frictionless casters fore and aft of link
    `base`."""
    casters = "".join(
        f'<collision name="caster_{n}"><pose>{x} 0 0 0 0 0</pose><geometry><sphere><radius>{R}'
        "</radius></sphere></geometry><surface><friction><ode><mu>0</mu><mu2>0</mu2></ode>"
        "</friction></surface></collision>"
        for n, x in (("front", 0.12), ("rear", -0.12))
    )
    chassis = _sdf_chassis(0.0, 0.3, base).replace("</link>", casters + "</link>", 1)
    wheels = _sdf_wheel("wheel_left", base, f"0 {TRACK / 2} 0") + _sdf_wheel(
        "wheel_right", base, f"0 {-TRACK / 2} 0"
    )
    return f'<sdf version="1.8"><model name="{model}">{chassis}{wheels}{plugin}</model></sdf>'


def sdf_ackermann(plugin: str) -> str:
    """An SDF car: rear wheels `rear_left_joint`/`rear_right_joint` on the origin's axle, front
    wheels under `left_steering_joint`/`right_steering_joint`, WHEEL_BASE ahead."""
    parts = [_sdf_chassis(WHEEL_BASE / 2)]
    for side, y in (("left", TRACK / 2), ("right", -TRACK / 2)):
        parts.append(_sdf_wheel(f"rear_{side}", "base_link", f"0 {y} 0"))
        parts.append(
            f'<link name="{side}_knuckle"><pose relative_to="{side}_steering_joint"/><inertial>'
            "<mass>0.1</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy><izz>1e-4</izz></inertia>"
            f'</inertial></link><joint name="{side}_steering_joint" type="revolute">'
            f'<pose relative_to="base_link">{WHEEL_BASE} {y} 0 0 0 0</pose><parent>base_link'
            f"</parent><child>{side}_knuckle</child><axis><xyz>0 0 1</xyz><limit><lower>-0.8"
            "</lower><upper>0.8</upper><effort>50</effort><velocity>4</velocity></limit></axis>"
            "</joint>"
        )
        parts.append(_sdf_wheel(f"front_{side}", f"{side}_knuckle", "0 0 0"))
    body = "".join(parts)
    return f'<sdf version="1.8"><model name="car">{body}{plugin}</model></sdf>'


def gz_vehicle(tags: str = "") -> str:
    """gz-sim's diff_drive example's `vehicle_blue` at this module's size: `sdf_diff_drive` with
    a `chassis` link and gz-sim's DiffDrive, its topic and frame `tags` added."""
    plugin = (
        '<plugin filename="gz-sim-diff-drive-system" name="gz::sim::systems::DiffDrive">'
        "<left_joint>wheel_left_joint</left_joint><right_joint>wheel_right_joint</right_joint>"
        f"<wheel_separation>{TRACK}</wheel_separation><wheel_radius>{R}</wheel_radius>"
        f"{tags}</plugin>"
    )
    return sdf_diff_drive(plugin, model="vehicle_blue", base="chassis")


STATIC_GROUND = (
    '<sdf version="1.8"><model name="ground_plane"><static>true</static><link name="link">'
    '<collision name="c"><geometry><box><size>1 1 0.1</size></box></geometry></collision>'
    "</link></model></sdf>"
)
"""A static model: no joint moves, nothing of it is published."""


ARM_INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)


def arm_urdf(plugin: str) -> str:
    """A base fixed to the world, `shoulder` and `elbow` about z, 0.3 m apart."""
    return f"""<robot name="arm"><link name="world"/><link name="base">{ARM_INERTIAL}</link>
      <link name="upper">{ARM_INERTIAL}</link><link name="fore">{ARM_INERTIAL}</link>
      <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
        <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="100" velocity="3"/></joint>
      <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
        <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/>
        <limit lower="-2" upper="2" effort="100" velocity="3"/></joint>
      <gazebo>{plugin}</gazebo></robot>"""


def arm_sdf(plugin: str) -> str:
    """`arm_urdf` as an SDF model fixed to the world, the plugin inside the model."""
    link = (
        '<link name="{n}"><pose>{x} 0 0 0 0 0</pose><inertial><mass>1</mass><inertia><ixx>0.01'
        "</ixx><iyy>0.01</iyy><izz>0.01</izz></inertia></inertial></link>"
    )
    joint = (
        '<joint name="{n}" type="revolute"><parent>{p}</parent><child>{c}</child><axis><xyz>0 0 1'
        "</xyz><limit><lower>-2</lower><upper>2</upper><effort>100</effort><velocity>3</velocity>"
        "</limit></axis></joint>"
    )
    parts = [link.format(n=n, x=x) for n, x in (("base", 0), ("upper", 0), ("fore", 0.3))]
    parts += ['<joint name="fix" type="fixed"><parent>world</parent><child>base</child></joint>']
    parts += [joint.format(n="shoulder", p="base", c="upper")]
    parts += [joint.format(n="elbow", p="upper", c="fore")]
    return f'<sdf version="1.8"><model name="arm">{"".join(parts)}{plugin}</model></sdf>'
