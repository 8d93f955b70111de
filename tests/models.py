"""Small named robot descriptions for tests: URDF text factories and a writer to a tmp dir.

Each factory returns URDF text; `write_urdf(tmp_path, text)` puts it in a file. Inertias are
those of the solid shapes, so oracles can compute masses and heights by hand.
"""

from __future__ import annotations

from pathlib import Path


def write_urdf(directory: Path, text: str, name: str = "robot.urdf") -> Path:
    """Write URDF `text` to `directory/name` and return the path."""
    path = Path(directory) / name
    path.write_text(text, encoding="utf-8")
    return path


def _sphere_inertial(mass: float, radius: float) -> str:
    i = 0.4 * mass * radius**2
    return (
        f'<inertial><mass value="{mass}"/>'
        f'<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _box_inertial(mass: float, sx: float, sy: float, sz: float) -> str:
    ixx = mass * (sy**2 + sz**2) / 12
    iyy = mass * (sx**2 + sz**2) / 12
    izz = mass * (sx**2 + sy**2) / 12
    return (
        f'<inertial><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _gazebo(reference: str, **tags: object) -> str:
    body = "".join(f"<{tag}>{value}</{tag}>" for tag, value in tags.items() if value is not None)
    return f'<gazebo reference="{reference}">{body}</gazebo>' if body else ""


def ball_on_plane(
    mass: float, kp: float | None = None, kd: float | None = None, mu: float | None = None
) -> str:
    """A free ball (radius 0.1 m, `mass` [kg]) with Gazebo kp [N/m], kd [N s/m] and mu1 = mu2 =
    `mu` on 'ball'."""
    return f"""<robot name="ball">
  <link name="ball">
    {_sphere_inertial(mass, 0.1)}
    <collision><geometry><sphere radius="0.1"/></geometry></collision>
    <visual><geometry><sphere radius="0.1"/></geometry></visual>
  </link>
  {_gazebo("ball", kp=kp, kd=kd, mu1=mu, mu2=mu)}
</robot>"""


def block(
    mu: float | None = None,
    size: float = 0.1,
    mass: float = 1.0,
    name: str = "block",
    height: float | None = None,
) -> str:
    """A free cube of edge `size` [m] (a plate when `height` [m] is given) and `mass` [kg]; `mu`
    sets Gazebo mu1 and mu2 on it."""
    h = size if height is None else height
    return f"""<robot name="{name}">
  <link name="{name}">
    {_box_inertial(mass, size, size, h)}
    <collision><geometry><box size="{size} {size} {h}"/></geometry></collision>
  </link>
  {_gazebo(name, mu1=mu, mu2=mu)}
</robot>"""


def wheeled_cart(mu: float = 1.0, mass: float = 40.0, limit: str = "") -> str:
    """A 0.8×0.5×0.2 m chassis of `mass` [kg] on four 0.5 kg wheels of radius 0.1 m (axles at the
    chassis' underside, so it clears the ground by 0.1 m); `mu` sets mu1 and mu2 on the wheels,
    `limit` is the axles' `<limit …/>` element (effort and velocity: a motor on each)."""
    wheels, joints, tags = [], [], []
    for name, x, y in (("lf", 0.3, 0.3), ("rf", 0.3, -0.3), ("lb", -0.3, 0.3), ("rb", -0.3, -0.3)):
        wheels.append(
            f'<link name="{name}">{_box_inertial(0.5, 0.1, 0.1, 0.1)}<collision>'
            '<origin rpy="1.5708 0 0"/><geometry><cylinder radius="0.1" length="0.05"/>'
            "</geometry></collision></link>"
        )
        joints.append(
            f'<joint name="{name}_axle" type="continuous"><parent link="chassis"/>'
            f'<child link="{name}"/><origin xyz="{x} {y} -0.1"/><axis xyz="0 1 0"/>{limit}</joint>'
        )
        tags.append(_gazebo(name, mu1=mu, mu2=mu))
    return f"""<robot name="cart">
  <link name="chassis">{_box_inertial(mass, 0.8, 0.5, 0.2)}
    <collision><geometry><box size="0.8 0.5 0.2"/></geometry></collision></link>
  {"".join(wheels)}{"".join(joints)}{"".join(tags)}
</robot>"""


def slab(mu: float, name: str = "slab") -> str:
    """A static 2 m × 2 m × 0.1 m slab (top face at z = 0.05 m) with Gazebo μ on its surface."""
    return f"""<robot name="{name}">
  <link name="{name}">
    {_box_inertial(100.0, 2.0, 2.0, 0.1)}
    <collision><geometry><box size="2 2 0.1"/></geometry></collision>
  </link>
  {_gazebo(name, mu1=mu, mu2=mu)}
  <gazebo><static>true</static></gazebo>
</robot>"""


def block_on_incline(mu: float) -> str:
    """The cube of `block(mu)`; tests tilt gravity by θ rather than the plane (same physics)."""
    return block(mu)


def hinged_bar(plugin: str, effort: float = 1000.0) -> str:
    """A 1 kg bar, its mass 0.5 m out along x, on a y-axis hinge to the world within ±3 rad:
    gravity loads it by 4.905·cos q N m, its inertia about the hinge is 0.2501 kg m². `plugin`
    is the robot's one `<gazebo>` plugin (the controller under test)."""
    return f"""<robot name="bar"><link name="world"/>
  <link name="bar"><inertial><origin xyz="0.5 0 0"/><mass value="1"/><inertia ixx="1e-4"
    iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="world"/><child link="bar"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="{effort:g}" velocity="10"/></joint>
  <gazebo>{plugin}</gazebo></robot>"""


def pendulum_pair(gravity_off_link: str | None = "left", tag: str = "turnGravityOff") -> str:
    """Two sibling pendulums on a world-fixed base, both horizontal at rest (hinges about y).

    Links 'left' and 'right' (1 kg point-like spheres 0.5 m out along ±x). `tag` is written on
    `gravity_off_link`: "turnGravityOff" (value true) or "gravity" (value false).
    """
    value = "true" if tag == "turnGravityOff" else "false"
    tags = f'<gazebo reference="{gravity_off_link}"><{tag}>{value}</{tag}></gazebo>'
    arms = "".join(_pendulum_arm(side, sign) for side, sign in (("left", 1), ("right", -1)))
    return f"""<robot name="pendulums">
  <link name="world"/>
  <link name="base">{_box_inertial(1.0, 0.1, 0.1, 0.1)}</link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1"/></joint>
  {arms}
  {tags if gravity_off_link else ""}
</robot>"""


def _pendulum_arm(side: str, sign: int) -> str:
    return f"""<link name="{side}">
    <inertial><origin xyz="{0.5 * sign} 0 0"/><mass value="1"/>
      <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="{side}_hinge" type="continuous"><parent link="base"/><child link="{side}"/>
    <axis xyz="0 1 0"/></joint>"""


def falling_sibling(self_collide_link: str | None, model_self_collide: bool = False) -> str:
    """Two sibling links of a world-fixed base: a box 'dropper' falling onto a plate 'plate'.

    'plate' (0.4 × 0.4 × 0.02 m, top face at z = 0.01 m) turns on a vertical hinge, so gravity
    leaves it in place; 'dropper' (0.1 m cube, 1 kg) slides on a vertical prismatic joint from
    z = 0.3 m (joint 0) down to the joint's lower limit −1 m. The two links are not joined by a
    joint, so under Gazebo's rule they touch only when one of them has selfCollide: then the
    cube rests on the plate at joint position 0.01 + 0.05 − 0.3 = −0.24 m.
    """
    tags = _gazebo(self_collide_link, selfCollide="true") if self_collide_link else ""
    model = "<gazebo><self_collide>true</self_collide></gazebo>" if model_self_collide else ""
    return f"""<robot name="siblings">
  <link name="world"/>
  <link name="base">{_box_inertial(1.0, 0.1, 0.1, 0.1)}</link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <link name="plate">
    {_box_inertial(1.0, 0.4, 0.4, 0.02)}
    <collision><geometry><box size="0.4 0.4 0.02"/></geometry></collision>
  </link>
  <joint name="turn" type="continuous"><parent link="base"/><child link="plate"/>
    <axis xyz="0 0 1"/></joint>
  <link name="dropper">
    {_box_inertial(1.0, 0.1, 0.1, 0.1)}
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="drop" type="prismatic"><parent link="base"/><child link="dropper"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="100" velocity="10"/></joint>
  {tags}
  {model}
</robot>"""


def mimic_pincer(offset: float = 0.2, multiplier: float = -1.0) -> str:
    """A fixed-base pincer 1 m up: 'lead' (range ±1 rad) and 'follow' (range ±1 rad, mimic
    `offset + multiplier · lead`), both hinges about y with a 0.5 kg, 0.2 m box finger whose
    centre is 0.1 m along x, so gravity swings them; only 'lead' has a motor."""
    limit = '<limit lower="-1" upper="1" effort="5" velocity="3"/>'
    mimic = f'<mimic joint="lead" multiplier="{multiplier}" offset="{offset}"/>'
    finger = _box_inertial(0.5, 0.2, 0.02, 0.02).replace("<mass", '<origin xyz="0.1 0 0"/><mass')

    def joint(name: str, child: str, y: float, extra: str = "") -> str:
        return (
            f'<joint name="{name}" type="revolute"><parent link="base"/><child link="{child}"/>'
            f'<origin xyz="0 {y} 0"/><axis xyz="0 1 0"/>{limit}{extra}</joint>'
        )

    return f"""<robot name="pincer">
  <link name="world"/>
  <link name="base">{_box_inertial(1.0, 0.1, 0.1, 0.1)}</link>
  <link name="a">{finger}</link>
  <link name="b">{finger}</link>
  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1"/></joint>
  {joint("lead", "a", 0.05)}
  {joint("follow", "b", -0.05, mimic)}
</robot>"""


# ---- MJCF factories for the world engine (tests/twin_cli/test_world*.py) ----


def mjcf_ball(radius: float = 0.1, mass: float = 1.0, name: str = "ball") -> str:
    """A free sphere (`radius` [m], `mass` [kg]) whose centre starts at the origin."""
    return f"""<mujoco model="{name}"><worldbody><body name="ball">
  <freejoint name="root"/><geom type="sphere" size="{radius}" mass="{mass}"/>
</body></worldbody></mujoco>"""


def mjcf_box(
    half: tuple[float, float, float] = (0.1, 0.1, 0.1),
    mass: float = 1.0,
    free: bool = True,
    name: str = "box",
    mu: float = 1.0,
) -> str:
    """A box of half-sizes `half` [m] centred at the origin; static (no joint) unless `free`."""
    joint = '<freejoint name="root"/>' if free else ""
    size = " ".join(str(h) for h in half)
    return f"""<mujoco model="{name}"><worldbody><body name="box">{joint}
  <geom type="box" size="{size}" mass="{mass}" friction="{mu} 0.005 0.0001"/>
</body></worldbody></mujoco>"""


def mjcf_arm(
    lower: float, upper: float, effort: float, name: str = "arm", limit_timeconst: float = 0.005
) -> str:
    """A fixed-base arm: hinge 'shoulder' about y, range [lower, upper] [rad], a 0.5 m, 1 kg
    capsule link, and a motor actuator with ctrlrange ±effort [N m] (the converter's contract).
    The limit's time constant defaults to the converter's mapping of Gazebo's stopErp 0.2 at
    1 ms (`converters.gazebo.contact.limit_solref`: 0.005 s)."""
    return f"""<mujoco model="{name}"><compiler angle="radian"/>
  <worldbody><body name="base" pos="0 0 1">
  <geom type="box" size="0.05 0.05 0.05" mass="1" contype="0" conaffinity="0"/>
  <body name="link"><joint name="shoulder" type="hinge" axis="0 1 0" range="{lower} {upper}"
      limited="true" solreflimit="{limit_timeconst} 1"/>
    <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.03" mass="1" contype="0" conaffinity="0"/>
  </body></body></worldbody>
  <actuator><motor name="shoulder" joint="shoulder" ctrlrange="{-effort} {effort}"
      ctrllimited="true"/></actuator></mujoco>"""


def mjcf_with_home(name: str = "homed", hinge: float = 0.7, z: float = 0.5) -> str:
    """A free body with a hinge and a `home` key: hinge at `hinge` [rad], body at height `z`."""
    return f"""<mujoco model="{name}"><worldbody><body name="base">
  <freejoint name="root"/><geom type="box" size="0.1 0.1 0.1" mass="1"/>
  <body name="tip" pos="0.2 0 0"><joint name="hinge" type="hinge" axis="0 0 1"/>
    <geom type="sphere" size="0.05" mass="0.1"/></body></body></worldbody>
  <keyframe><key name="home" qpos="0 0 {z} 1 0 0 0 {hinge}"/></keyframe></mujoco>"""


def mjcf_stiff_spring(name: str = "spring") -> str:
    """A fixed-base hinge with stiffness 1e9 N m/rad on 1e-6 kg m², started off its rest angle:
    explicit integration blows up within a few steps (MuJoCo's bad-qacc warning)."""
    return f"""<mujoco model="{name}"><worldbody><body name="base" pos="0 0 2">
  <body name="bob"><joint name="spring" type="hinge" axis="0 0 1" stiffness="1e9" springref="1"/>
    <geom type="sphere" size="0.01" mass="1e-4" contype="0" conaffinity="0"/></body>
</body></worldbody></mujoco>"""


def _control_inertial(mass: float, moment: float) -> str:
    return (
        f'<inertial><mass value="{mass}"/><inertia ixx="{moment}" iyy="{moment}" '
        f'izz="{moment}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


# A fixed rig: a disc on a continuous joint (effort 2 N m, 3 rad/s, effort and velocity
# interfaces) and a slider (range -0.2..0.3 m, 0.5 m/s, a position interface bounded -0.1..0.25).
CONTROL_RIG = f"""<robot name="wheel">
  <link name="world"/>
  <link name="base">{_control_inertial(1, 1)}</link>
  <link name="disc">{_control_inertial(1, 0.01)}</link>
  <link name="slider">{_control_inertial(0.5, 0.001)}</link>
  <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="spin" type="continuous"><parent link="base"/><child link="disc"/>
    <axis xyz="0 0 1"/><limit effort="2" velocity="3"/></joint>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="slider"/>
    <axis xyz="1 0 0"/><limit lower="-0.2" upper="0.3" effort="50" velocity="0.5"/></joint>
  <ros2_control name="rig" type="system">
    <joint name="spin">
      <command_interface name="effort"/><command_interface name="velocity"/>
    </joint>
    <joint name="slide">
      <command_interface name="position">
        <param name="min">-0.1</param><param name="max">0.25</param>
      </command_interface>
    </joint>
  </ros2_control>
</robot>
"""


# Two wheels on continuous joints `lj`/`rj`, 0.2 m apart: the links a diff-drive plugin names.
TWO_WHEELS = """
  <link name="base"><inertial><mass value="2"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0"
    ixz="0" iyz="0"/></inertial></link>
  <link name="l"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0"
    ixz="0" iyz="0"/></inertial></link>
  <link name="r"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0"
    ixz="0" iyz="0"/></inertial></link>
  <joint name="lj" type="continuous"><parent link="base"/><child link="l"/>
    <origin xyz="0 0.1 0"/><axis xyz="0 1 0"/></joint>
  <joint name="rj" type="continuous"><parent link="base"/><child link="r"/>
    <origin xyz="0 -0.1 0"/><axis xyz="0 1 0"/></joint>
"""


def two_wheel_bot(plugins: str) -> str:
    """`TWO_WHEELS` with `plugins` (XML) in the model's `<gazebo>` block."""
    return f'<robot name="bot">{TWO_WHEELS}<gazebo>{plugins}</gazebo></robot>'
