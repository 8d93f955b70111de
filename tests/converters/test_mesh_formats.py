"""DAE, STL and OBJ meshes of a package the test writes: each at its file's unit and URDF scale."""

from __future__ import annotations

from pathlib import Path

import pytest
from mesh_models import MESH_LINKS, geom_extents, write_mesh_package

from converters.pipeline import convert_full


def test_dae_stl_and_obj_meshes_keep_their_size_unit_and_scale(tmp_path: Path) -> None:
    urdf = write_mesh_package(tmp_path)
    package = urdf.parent.parent
    done = convert_full(urdf, package_paths={package.name: package})
    model = done.spec.compile()
    for mesh in MESH_LINKS:
        for kind in ("visual", "collision"):
            measured = geom_extents(model, mesh.link, kind)
            assert measured == pytest.approx(mesh.extents, rel=1e-6), (
                f"{mesh.file} ({kind}): size [m] {measured}, the box is {mesh.extents}"
            )


def test_a_dae_mesh_found_through_ros_package_path(tmp_path: Path, monkeypatch) -> None:
    """`package://` resolves through ROS_PACKAGE_PATH as well as through --package."""
    packages = tmp_path / "share"
    urdf = write_mesh_package(packages)
    elsewhere = tmp_path / "elsewhere" / "robot.urdf"  # no package above it to find by walking up
    elsewhere.parent.mkdir()
    elsewhere.write_text(urdf.read_text())
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(packages))
    model = convert_full(elsewhere).spec.compile()
    dae = MESH_LINKS[0]
    assert geom_extents(model, dae.link, "visual") == pytest.approx(dae.extents, rel=1e-6)
