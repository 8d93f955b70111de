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
