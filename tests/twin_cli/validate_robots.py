"""Deliberately broken robots for `twin validate` tests: one small URDF family, one flaw each.

`crate()` is a floating 5 kg box (0.3 × 0.3 × 0.1 m) with an 'arm' (0.5 kg, 0.04 × 0.04 × 0.2 m
box standing up from the crate's top) on a revolute joint 'elbow' about y, limits ±1 rad,
effort 10 N m. Each keyword breaks one thing; the default robot passes every check.
"""

from __future__ import annotations

from pathlib import Path


def box_inertial(mass: float, sx: float, sy: float, sz: float, origin: str = "0 0 0") -> str:
    """A uniform solid box's <inertial> [kg], sizes [m]."""
    ixx, iyy, izz = (mass * (a * a + b * b) / 12 for a, b in ((sy, sz), (sx, sz), (sx, sy)))
    return (
        f'<inertial><origin xyz="{origin}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _box_link(name: str, size: str, origin: str, inertial: str, mesh: str | None = None) -> str:
    shape = f'<mesh filename="{mesh}"/>' if mesh else f'<box size="{size}"/>'
    return f"""<link name="{name}">
    {inertial}
    <collision><origin xyz="{origin}"/><geometry>{shape}</geometry></collision>
    <visual><origin xyz="{origin}"/><geometry><box size="{size}"/></geometry></visual>
  </link>"""


def crate(
    *,
    arm_inertial: bool = True,
    arm_mass: float = 0.5,
    arm_inertia: float | None = None,
    kp: float | None = None,
    flap_overlaps_arm: bool = False,
    arm_self_collide: bool = False,
    arm_mesh: str | None = None,
    elbow_limit: tuple[float, float] = (-1.0, 1.0),
    elbow_velocity: float = 5.0,
    fixed: bool = False,
) -> str:
    """URDF text of the crate, broken as asked.

    Args:
        arm_inertial: False drops the arm's <inertial> (a moving link without mass).
        arm_mass: the arm's mass [kg].
        arm_inertia: every principal moment of the arm [kg m²] (None: the solid box's).
        kp: Gazebo contact stiffness [N/m] on the crate (None: Gazebo's rigid default).
        flap_overlaps_arm: add a sibling link 'flap' whose box overlaps the arm by 2 cm.
        arm_self_collide: Gazebo selfCollide on the arm (then arm and flap collide).
        arm_mesh: a mesh file for the arm's collision instead of its box.
        elbow_limit: the elbow's (lower, upper) [rad].
        elbow_velocity: the elbow's velocity limit [rad/s].
        fixed: weld the crate to the world (a fixed joint to a link named `world`).
    """
    if arm_inertia is None:
        arm = box_inertial(arm_mass, 0.04, 0.04, 0.2, "0 0 0.1") if arm_inertial else ""
    else:
        i = arm_inertia
        arm = (
            f'<inertial><origin xyz="0 0 0.1"/><mass value="{arm_mass}"/>'
            f'<inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>'
        )
    flap = ""
    if flap_overlaps_arm:
        inertial = box_inertial(0.5, 0.04, 0.04, 0.2, "0.02 0 0.1")
        flap = f"""{_box_link("flap", "0.04 0.04 0.2", "0.02 0 0.1", inertial)}
  <joint name="hinge" type="revolute"><parent link="crate"/><child link="flap"/>
    <origin xyz="0 0 0.05"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="5"/></joint>"""
    gazebo = f'<gazebo reference="crate"><kp>{kp}</kp><kd>50</kd></gazebo>' if kp else ""
    if arm_self_collide:
        gazebo += '<gazebo reference="arm"><selfCollide>true</selfCollide></gazebo>'
    if fixed:
        gazebo += (
            '<link name="world"/><joint name="weld" type="fixed">'
            '<parent link="world"/><child link="crate"/><origin xyz="0 0 0.5"/></joint>'
        )
    return f"""<robot name="crate">
  {_box_link("crate", "0.3 0.3 0.1", "0 0 0", box_inertial(5.0, 0.3, 0.3, 0.1))}
  {_box_link("arm", "0.04 0.04 0.2", "0 0 0.1", arm, arm_mesh)}
  <joint name="elbow" type="revolute"><parent link="crate"/><child link="arm"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/>
    <limit lower="{elbow_limit[0]}" upper="{elbow_limit[1]}" effort="10"
           velocity="{elbow_velocity}"/>
    <dynamics damping="0.05"/></joint>
  {flap}
  {gazebo}
</robot>"""


def write(directory: Path, text: str, name: str = "crate.urdf") -> Path:
    """Write robot text into `directory` and return its path."""
    path = Path(directory) / name
    path.write_text(text, encoding="utf-8")
    return path


def dense_sphere_stl(directory: Path, subdivisions: int = 5) -> Path:
    """An icosphere STL of radius 2 cm; subdivisions 5 gives 20,480 triangles."""
    import trimesh

    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.02)
    path = Path(directory) / f"sphere{subdivisions}.stl"
    mesh.export(path)
    return path


def unenforced_limit_mjcf(directory: Path) -> Path:
    """The crate as MJCF with the elbow's range kept but its enforcement turned off."""
    import mujoco

    from converters.pipeline import convert

    spec, _ = convert(write(directory, crate()))
    spec.joint("elbow").limited = mujoco.mjtLimited.mjLIMITED_FALSE
    path = Path(directory) / "crate_unlimited.xml"
    path.write_text(spec.to_xml(), encoding="utf-8")
    return path


# ---- one flaw each, for the verdict tests (tests/twin_cli/validate/test_validate_verdicts.py) ----

PENDULUM_MASS = 1.0  # [kg] point-like bob of `pendulum`
PENDULUM_LENGTH = 0.5  # [m] from the hinge to the bob
PENDULUM_RANGE = 0.5  # [rad] the hinge's range is ±this about horizontal


def pendulum(effort: float) -> str:
    """A horizontal pendulum 1 m above the world: 'bob' (PENDULUM_MASS at PENDULUM_LENGTH along
    +x, inertia 1e-4 kg m²) on hinge 'shoulder' about y, range ±PENDULUM_RANGE, `effort` [N m],
    velocity 2 rad/s. Its gravity load is m·g·L·cos q: 4.9 N m level, 4.3 N m at the stops."""
    i = 1e-4
    return f"""<robot name="pendulum">
  <link name="world"/>
  <link name="base">{box_inertial(1.0, 0.1, 0.1, 0.1)}</link>
  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1"/></joint>
  <link name="bob">
    <inertial><origin xyz="{PENDULUM_LENGTH} 0 0"/><mass value="{PENDULUM_MASS}"/>
      <inertia ixx="{i}" iyy="{i}" izz="{i}" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="bob"/>
    <axis xyz="0 1 0"/>
    <limit lower="{-PENDULUM_RANGE}" upper="{PENDULUM_RANGE}" effort="{effort}" velocity="2"/>
  </joint>
</robot>"""


def scout(lidar_link: str = "lidar_link") -> str:
    """A 2 kg box base with a mast link 'lidar_link' 0.2 m up, and a lidar whose
    `<gazebo reference>` is `lidar_link` (a misspelt name leaves it on no link)."""
    return f"""<robot name="scout">
  <link name="base">{box_inertial(2.0, 0.4, 0.3, 0.1)}
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision></link>
  <joint name="mast" type="fixed"><parent link="base"/><child link="lidar_link"/>
    <origin xyz="0 0 0.2"/></joint>
  <link name="lidar_link">{box_inertial(0.1, 0.05, 0.05, 0.05)}
    <collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link>
  <gazebo reference="{lidar_link}"><sensor type="ray" name="front_lidar">
    <update_rate>10</update_rate><ray><scan><horizontal><samples>31</samples>
    <min_angle>-0.5</min_angle><max_angle>0.5</max_angle></horizontal></scan>
    <range><min>0.1</min><max>5</max></range></ray></sensor></gazebo>
</robot>"""


IMU_NOISE = 1e-4  # [m/s²] the accelerometer noise σ `imu_box` declares on every axis


def imu_box(kp: float | None = None) -> str:
    """A free 2 kg box (0.3 × 0.2 × 0.1 m) carrying an IMU 'imu' at 200 Hz that declares
    IMU_NOISE on its accelerometer; `kp` [N/m] on the box (None: Gazebo's rigid default)."""
    axes = "".join(
        f'<{a}><noise type="gaussian"><mean>0</mean><stddev>{IMU_NOISE}</stddev></noise></{a}>'
        for a in "xyz"
    )
    contact = f"<kp>{kp}</kp><kd>1</kd>" if kp is not None else ""
    return f"""<robot name="imu_box">
  <link name="base">{box_inertial(2.0, 0.3, 0.2, 0.1)}
    <collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision></link>
  <gazebo reference="base">{contact}<sensor type="imu" name="imu"><update_rate>200</update_rate>
    <imu><linear_acceleration>{axes}</linear_acceleration></imu></sensor></gazebo>
</robot>"""


FOLD_DEPTH = 0.02  # [m] how deep `folded_arm`'s 'hand' overlaps its 'upper' at the zero posture


def folded_arm() -> str:
    """A fixed arm 0.5 m up in the x-z plane, hinges about y: 'upper' (0.3 m along +x from
    'shoulder'), 'fore' (0.3 m further, 'elbow') and 'hand' (on 'wrist' at the forearm's end,
    folded back: a 0.2 m box centred 0.4 m back and 3 cm up), which overlaps 'upper' by
    FOLD_DEPTH at the zero posture. 'hand' has selfCollide, so that pair collides; `-J
    wrist=-1.5` hangs the hand down, clear of every link. Joints ±3 rad, 50 N m."""
    limit = '<limit lower="-3" upper="3" effort="50" velocity="2"/>'

    def bar(name: str, mass: float, length: float, origin: str) -> str:
        inertial = box_inertial(mass, length, 0.05, 0.05, origin)
        return f"""<link name="{name}">{inertial}<collision><origin xyz="{origin}"/>
    <geometry><box size="{length} 0.05 0.05"/></geometry></collision></link>"""

    def hinge(name: str, parent: str, child: str, x: float) -> str:
        return (
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{x} 0 0"/><axis xyz="0 1 0"/>{limit}</joint>'
        )

    lift = 0.05 - FOLD_DEPTH  # hand centre above upper's: half heights 0.025 + 0.025 − depth
    return f"""<robot name="folded_arm">
  <link name="world"/>
  <link name="base">{box_inertial(1.0, 0.05, 0.05, 0.05)}</link>
  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 0.5"/></joint>
  {bar("upper", 1.0, 0.3, "0.15 0 0")}
  {bar("fore", 1.0, 0.3, "0.15 0 0")}
  {bar("hand", 0.5, 0.2, f"-0.4 0 {lift}")}
  {hinge("shoulder", "base", "upper", 0.0)}
  {hinge("elbow", "upper", "fore", 0.3)}
  {hinge("wrist", "fore", "hand", 0.3)}
  <gazebo reference="hand"><selfCollide>true</selfCollide></gazebo>
</robot>"""


def caster_base(mu: float) -> str:
    """A free 5 kg box base (0.4 × 0.3 × 0.1 m) standing on three ball casters (radius 3 cm,
    fixed joints, so lumped into 'base') whose Gazebo μ (mu1, mu2) is `mu`."""
    casters, tags = [], []
    for name, x, y in (("caster_front", 0.15, 0.0), ("caster_left", -0.15, 0.1),
                       ("caster_right", -0.15, -0.1)):  # fmt: skip
        casters.append(
            f'<link name="{name}">{box_inertial(0.05, 0.06, 0.06, 0.06)}<collision><geometry>'
            '<sphere radius="0.03"/></geometry></collision></link>'
            f'<joint name="{name}_mount" type="fixed"><parent link="base"/>'
            f'<child link="{name}"/><origin xyz="{x} {y} -0.07"/></joint>'
        )
        tags.append(f'<gazebo reference="{name}"><mu1>{mu}</mu1><mu2>{mu}</mu2></gazebo>')
    return f"""<robot name="caster_base">
  <link name="base">{box_inertial(5.0, 0.4, 0.3, 0.1)}
    <collision><geometry><box size="0.4 0.3 0.1"/></geometry></collision></link>
  {"".join(casters)}{"".join(tags)}
</robot>"""
