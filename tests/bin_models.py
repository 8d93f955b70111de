"""A concave static bin (an open-topped box) as a mesh and a URDF, built from formulas: what a
ball must rest on when its collision geometry is decomposed (the floor) or a hull (the rim);
and that ball."""

from __future__ import annotations

from pathlib import Path

import numpy as np

# Bin: an open-topped box, outer 300 x 300 x 200 mm, walls and floor 20 mm, centred on its
# bounding box (floor top at BIN_FLOOR - BIN_OUTER[2] / 2 in the mesh frame) [m].
BIN_OUTER = (0.30, 0.30, 0.20)
BIN_WALL = 0.02
BIN_FLOOR = 0.02
BALL_RADIUS = 0.03  # [m]


def bin_mesh() -> tuple[np.ndarray, np.ndarray]:
    """The closed bin (box minus its cavity, 28 triangles); (vertices [m], faces)."""
    import trimesh

    outer = trimesh.creation.box(BIN_OUTER)
    cavity = trimesh.creation.box(
        (BIN_OUTER[0] - 2 * BIN_WALL, BIN_OUTER[1] - 2 * BIN_WALL, BIN_OUTER[2])
    )
    cavity.apply_translation((0.0, 0.0, BIN_FLOOR))
    mesh = outer.difference(cavity)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def bin_urdf(directory, *, name: str = "bin") -> str:
    """A static URDF (welded to `world`, bottom on z = 0) whose one link is the bin mesh, written
    with its STL into `directory`; returns the URDF's path."""
    import trimesh

    trimesh.Trimesh(*bin_mesh(), process=False).export(directory / f"{name}.stl")
    lift = BIN_OUTER[2] / 2
    (directory / f"{name}.urdf").write_text(
        f"""<robot name="{name}">
  <link name="world"/>
  <joint name="fix" type="fixed"><parent link="world"/><child link="bin"/>
    <origin xyz="0 0 {lift}"/></joint>
  <link name="bin">
    <inertial><mass value="2.0"/>
      <inertia ixx="0.02" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{name}.stl"/></geometry></visual>
    <collision><geometry><mesh filename="{name}.stl"/></geometry></collision>
  </link>
</robot>
"""
    )
    return str(directory / f"{name}.urdf")


def ball_urdf(directory: Path) -> str:
    """A 50 g solid ball of BALL_RADIUS as a URDF in `directory`; its path."""
    mass = 0.05  # [kg]
    inertia = 0.4 * mass * BALL_RADIUS**2  # solid sphere, 2/5 m r^2 [kg m^2]
    (directory / "ball.urdf").write_text(
        f"""<robot name="ball"><link name="ball">
  <inertial><mass value="{mass}"/>
    <inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><sphere radius="{BALL_RADIUS}"/></geometry></collision>
</link></robot>
"""
    )
    return str(directory / "ball.urdf")


def bin_world(directory: Path, *, drop_z: float, bins: int = 1) -> str:
    """An SDF world file in `directory` with `bins` static bins (models `bin`, `bin_1`, …, 1 m
    apart along x, bottoms on z = 0, one STL beside the file) and the ball (BALL_RADIUS, 50 g)
    as a model at height `drop_z` [m] above the first bin's centre; returns its path."""
    import trimesh

    trimesh.Trimesh(*bin_mesh(), process=False).export(directory / "bin.stl")
    mass = 0.05  # [kg]
    inertia = 0.4 * mass * BALL_RADIUS**2  # solid sphere, 2/5 m r^2 [kg m^2]
    models = "".join(
        f"""  <model name="{"bin" if k == 0 else f"bin_{k}"}"><static>true</static>
    <pose>{k} 0 {BIN_OUTER[2] / 2} 0 0 0</pose>
    <link name="bin"><collision name="c"><geometry><mesh><uri>bin.stl</uri></mesh></geometry>
    </collision></link></model>
"""
        for k in range(bins)
    )
    (directory / "bin.world").write_text(
        f"""<?xml version="1.0"?>
<sdf version="1.9"><world name="bin">
{models}  <model name="ball"><pose>0 0 {drop_z} 0 0 0</pose><link name="ball">
    <inertial><mass>{mass}</mass><inertia><ixx>{inertia}</ixx><iyy>{inertia}</iyy>
      <izz>{inertia}</izz></inertia></inertial>
    <collision name="c"><geometry><sphere><radius>{BALL_RADIUS}</radius></sphere></geometry>
    </collision></link></model>
</world></sdf>
"""
    )
    return str(directory / "bin.world")
