"""Large generated meshes for the tests of bounded conversions and their progress."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def write_grid_obj(path: Path, faces: int) -> None:
    """A bumpy square of about `faces` triangles as OBJ text, with random heights so that no
    earlier run's mesh store holds it."""
    side = int(np.sqrt(faces / 2)) + 1
    x, y = np.meshgrid(np.linspace(0, 1, side), np.linspace(0, 1, side))
    z = np.random.default_rng().random(x.shape) * 0.01
    index = np.arange(side * side).reshape(side, side) + 1
    a, b = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    c, d = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    triangles = np.concatenate([np.stack([a, b, c], 1), np.stack([b, d, c], 1)])
    with path.open("w") as stream:
        np.savetxt(stream, np.stack([x.ravel(), y.ravel(), z.ravel()], 1), "v %.6f %.6f %.6f")
        np.savetxt(stream, triangles, "f %d %d %d")


def write_mesh_arm(root: Path, *, links: int = 8, faces: int = 17_000) -> Path:
    """A chain of `links` links on revolute joints, each drawn with its own bumpy square of about
    `faces` triangles (OBJ, `write_grid_obj`) and colliding as a box; returns the URDF.

    With the defaults the visual meshes are about 136,000 triangles, as franka_panda's with its
    hand, so a page that draws them costs what franka_panda's costs.
    """
    (root / "meshes").mkdir(parents=True, exist_ok=True)
    parts = []
    for i in range(links):
        write_grid_obj(root / "meshes" / f"link{i}.obj", faces)
        parts.append(
            f"""  <link name="link{i}">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="-0.05 -0.05 0" rpy="1.5708 0 0"/>
      <geometry><mesh filename="../meshes/link{i}.obj" scale="0.1 0.1 0.1"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
"""
        )
        if i:
            parts.append(
                f"""  <joint name="joint{i}" type="revolute">
    <parent link="link{i - 1}"/><child link="link{i}"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
"""
            )
    (root / "urdf").mkdir(exist_ok=True)
    urdf = root / "urdf" / "arm.urdf"
    urdf.write_text(f'<robot name="mesh_arm">\n{"".join(parts)}</robot>\n')
    return urdf
