"""Small mesh factories for the collision tests, built from formulas (no tunable fixtures)."""

from __future__ import annotations

import numpy as np

from converters.collision.plan import CollisionRequest

# Cup: outer radius 50 mm, wall 8 mm, floor 8 mm, rim at 80 mm [m].
CUP_OUTER_R = 0.05
CUP_INNER_R = 0.042
CUP_FLOOR = 0.008
CUP_RIM = 0.08


def cup_mesh(sections: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """A closed cup made by revolving its wall profile about z; (vertices [m], faces)."""
    import trimesh

    profile = np.array(
        [
            [0.0, 0.0],
            [CUP_OUTER_R, 0.0],
            [CUP_OUTER_R, CUP_RIM],
            [CUP_INNER_R, CUP_RIM],
            [CUP_INNER_R, CUP_FLOOR],
            [0.0, CUP_FLOOR],
        ]
    )
    mesh = trimesh.creation.revolve(profile, sections=sections)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def box_mesh(extents: tuple[float, float, float]) -> tuple[np.ndarray, np.ndarray]:
    """A closed box centred at the origin [m]."""
    import trimesh

    mesh = trimesh.creation.box(extents)
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


def request(key: str, mesh: tuple[np.ndarray, np.ndarray], link: str | None = None):
    """A CollisionRequest for `mesh` on link `link` (default: the key's first segment)."""
    vertices, faces = mesh
    link = link or key.split("/")[0]
    return CollisionRequest(key, link, f"{link}.stl", (1.0, 1.0, 1.0), vertices, faces)


# Bin: an open-topped box, outer 300 x 300 x 200 mm, walls and floor 20 mm, centred on its
# bounding box (floor top at BIN_FLOOR - BIN_OUTER[2] / 2 in the mesh frame) [m].
BIN_OUTER = (0.30, 0.30, 0.20)
BIN_WALL = 0.02
BIN_FLOOR = 0.02


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
