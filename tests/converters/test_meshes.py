"""Binary STL is read with numpy exactly as trimesh reads it; other files still go to trimesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from corpus_registry import PACKAGES_ROOT, needs_corpus

from converters.errors import MeshError
from converters.mjcf.writer import stl_bytes
from converters.resources.meshes import (
    STL_HEADER_BYTES,
    MeshData,
    read_binary_stl,
    read_mesh_file,
    read_with_trimesh,
)

SEEDS = Path(__file__).resolve().parents[1] / "fuzz" / "seeds"
CORPUS_STL = sorted(PACKAGES_ROOT.rglob("*.[sS][tT][lL]")) if PACKAGES_ROOT.is_dir() else []
ASCII_TETRAHEDRON = """solid tet
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid tet
"""


def assert_same_mesh(ours: MeshData, oracle: MeshData, subject: str) -> None:
    """Bit-identical vertices (signed zeros included), faces, colour and texture flag."""
    assert ours.vertices.dtype == oracle.vertices.dtype, f"{subject}: vertex dtype"
    assert ours.vertices.shape == oracle.vertices.shape, f"{subject}: vertex count"
    assert ours.vertices.tobytes() == oracle.vertices.tobytes(), f"{subject}: vertex bytes [m]"
    assert ours.faces.dtype == oracle.faces.dtype, f"{subject}: face dtype"
    assert np.array_equal(ours.faces, oracle.faces), f"{subject}: faces"
    assert (ours.rgba, ours.textured) == (oracle.rgba, oracle.textured), f"{subject}: colour"


@needs_corpus
@pytest.mark.parametrize(
    "path",
    CORPUS_STL or [None],
    ids=lambda p: str(p.relative_to(PACKAGES_ROOT)) if p else "no-corpus",
)
def test_every_corpus_stl_reads_as_trimesh_reads_it(path: Path) -> None:
    ours = read_mesh_file(path, "link")
    assert_same_mesh(ours, read_with_trimesh(path, "link"), path.name)


@needs_corpus
def test_corpus_has_binary_stl_files_for_the_numpy_reader() -> None:
    binary = [p for p in CORPUS_STL if read_binary_stl(p, "link") is not None]
    assert len(binary) >= 10, f"only {len(binary)} of {len(CORPUS_STL)} corpus STL are binary"


def test_signed_zeros_duplicates_and_collapsed_triangles_match_trimesh(tmp_path: Path) -> None:
    vertices = np.array(
        [[-0.0, 0.0, 0.0], [1.0, -0.0, 0.0], [0.0, 1.0, -0.0], [0.0, 0.0, 1.0], [1.0, -0.0, 0.0]]
    )
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3], [1, 4, 2]])  # last: collapsed
    path = tmp_path / "tet.stl"
    path.write_bytes(stl_bytes(vertices, faces))
    ours = read_binary_stl(path, "link")
    assert ours is not None, "a well-formed binary STL takes the numpy path"
    assert_same_mesh(ours, read_with_trimesh(path, "link"), "tet.stl")
    assert ours.triangles == 4, "the collapsed triangle is dropped"


def test_upper_case_suffix_and_seed_cube_take_the_numpy_path(tmp_path: Path) -> None:
    path = tmp_path / "CUBE.STL"
    path.write_bytes((SEEDS / "cube.stl").read_bytes())
    assert read_binary_stl(path, "link") is not None
    assert_same_mesh(read_mesh_file(path, "link"), read_with_trimesh(path, "link"), "CUBE.STL")


def test_ascii_stl_is_left_to_trimesh(tmp_path: Path) -> None:
    path = tmp_path / "tet.stl"
    path.write_text(ASCII_TETRAHEDRON)
    assert read_binary_stl(path, "link") is None, "ASCII is not binary"
    mesh = read_mesh_file(path, "link")
    assert (len(mesh.vertices), mesh.triangles) == (4, 4), "vertices and triangles of the tet"


def test_binary_stl_without_triangles_is_a_mesh_error_naming_file_and_link(tmp_path: Path) -> None:
    path = tmp_path / "empty.stl"
    path.write_bytes(b"empty".ljust(STL_HEADER_BYTES - 4, b" ") + bytes(4))
    with pytest.raises(MeshError) as caught:
        read_mesh_file(path, "wheel")
    assert "empty.stl" in str(caught.value) and "wheel" in str(caught.value)
    assert "holds no triangles" in str(caught.value)
    with pytest.raises(MeshError, match="holds no triangles"):
        read_with_trimesh(path, "wheel")
