"""A mesh past MuJoCo's STL limit (200,000 faces) is written as MSH and reads back exactly;
`twin convert` of such a robot exited 70 (MuJoCo refused the STL the writer had written)."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from converters.mjcf.writer import STL_MAX_FACES, write_model
from converters.pipeline import convert_full
from tests.big_meshes import write_grid_obj

ROBOT = """<robot name="heavy"><link name="base">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial>
  <visual><geometry><mesh filename="bumps.obj"/></geometry></visual>
  <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
</link></robot>"""


def test_a_mesh_past_the_stl_limit_is_written_as_msh_and_reads_back_exactly(
    tmp_path: Path, monkeypatch
) -> None:
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    write_grid_obj(tmp_path / "bumps.obj", 250_000)
    (tmp_path / "heavy.urdf").write_text(ROBOT)
    done = convert_full(tmp_path / "heavy.urdf")
    reference = done.spec.compile()
    faces = int(reference.mesh_facenum.max())
    assert faces > STL_MAX_FACES, f"the mesh has only {faces} faces"
    robot_xml = write_model(done.spec, done.report, tmp_path / "out")
    assets = sorted(p.suffix for p in (tmp_path / "out" / "assets").iterdir())
    assert assets == [".msh"], assets
    loaded = mujoco.MjModel.from_xml_path(str(robot_xml))
    for field in ("mesh_vert", "mesh_face", "mesh_vertnum", "mesh_facenum", "body_mass"):
        same = np.array_equal(getattr(loaded, field), getattr(reference, field))
        assert same, f"{field} differs after the file"
