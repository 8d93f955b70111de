"""A robot package whose links use DAE, STL and OBJ meshes, written with trimesh (no corpus).

Each mesh is a box of known size, so a converted model can be checked against the box: the
COLLADA file declares inches (`<unit meter="0.0254"/>`), as real exports from CAD tools often do,
and the URDF scales the OBJ.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

INCH = 0.0254  # [m]


@dataclass(frozen=True)
class MeshLink:
    """One link of the package: its mesh file and the extents the converted geom must have."""

    link: str
    file: str
    size: tuple[float, float, float]  # [file units] the box as written
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)  # the URDF's <mesh scale>
    unit: float = 1.0  # [m per file unit]

    @property
    def extents(self) -> tuple[float, ...]:
        """[m] the box's size after the file's unit and the URDF's scale."""
        return tuple(s * k * self.unit for s, k in zip(self.size, self.scale, strict=True))


MESH_LINKS = (
    MeshLink("base", "base.dae", (10.0, 8.0, 4.0), unit=INCH),
    MeshLink("arm", "arm.stl", (0.05, 0.05, 0.3)),
    MeshLink("tool", "tool.obj", (0.1, 0.2, 0.1), scale=(0.5, 0.5, 2.0)),
)


def _write_box(path: Path, size: tuple[float, float, float], unit: float) -> None:
    import trimesh

    box = trimesh.creation.box(extents=size)
    if path.suffix == ".dae":
        text = trimesh.exchange.dae.export_collada(box).decode()
        # trimesh writes no unit (metres) and Y up; declare the unit as CAD exporters do, Z up.
        asset = f'<unit meter="{unit}" name="unit"/><up_axis>Z_UP</up_axis>'
        text, count = re.subn(r"<up_axis>[^<]*</up_axis>", asset, text)
        assert count == 1, "trimesh's COLLADA export has one <up_axis>"
        path.write_text(text)
    else:
        box.export(path)


def _link(mesh: MeshLink, package: str) -> str:
    uri = f"package://{package}/meshes/{mesh.file}"
    scale = " ".join(str(s) for s in mesh.scale)
    geometry = f'<geometry><mesh filename="{uri}" scale="{scale}"/></geometry>'
    return f"""  <link name="{mesh.link}">
    <inertial><mass value="1.0"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual>{geometry}</visual>
    <collision>{geometry}</collision>
  </link>
"""


def write_mesh_package(root: Path, package: str = "mesh_robot_description") -> Path:
    """Write `<root>/<package>` (package.xml, meshes/, urdf/robot.urdf); returns the URDF."""
    directory = root / package
    (directory / "meshes").mkdir(parents=True)
    (directory / "urdf").mkdir()
    (directory / "package.xml").write_text(
        f'<?xml version="1.0"?><package format="3"><name>{package}</name>'
        "<version>0.0.1</version><description>test</description>"
        "<maintainer email='t@example.com'>t</maintainer><license>MIT</license></package>"
    )
    for mesh in MESH_LINKS:
        _write_box(directory / "meshes" / mesh.file, mesh.size, mesh.unit)
    joints = "".join(
        f"""  <joint name="j{i}" type="revolute"><parent link="{a.link}"/><child link="{b.link}"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
"""
        for i, (a, b) in enumerate(zip(MESH_LINKS, MESH_LINKS[1:], strict=False))
    )
    links = "".join(_link(mesh, package) for mesh in MESH_LINKS)
    urdf = directory / "urdf" / "robot.urdf"
    urdf.write_text(f'<robot name="mesh_robot">\n{links}{joints}</robot>\n')
    return urdf


def geom_extents(model, link: str, kind: str) -> tuple[float, ...]:
    """[m] the world-axis size of a compiled mesh geom of `link` ('visual' or 'collision').

    MuJoCo stores a mesh in its principal-axes frame, so the vertices are placed in the world
    (at the model's zero posture, where every link is unrotated) before measuring.
    """
    import mujoco
    import numpy as np

    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    for geom_id in range(model.ngeom):
        geom = model.geom(geom_id)
        if model.body(geom.bodyid[0]).name == link and geom.name.startswith(f"{link}_{kind}"):
            mesh = geom.dataid[0]
            start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            local = model.mesh_vert[start : start + count].astype(float)
            placed = local @ data.geom_xmat[geom_id].reshape(3, 3).T
            return tuple(float(v) for v in np.ptp(placed, axis=0))
    raise AssertionError(f"no {kind} mesh geom of link {link!r}")
