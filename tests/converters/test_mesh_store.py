"""Conversions start fast: no mesh library for primitive robots, none for meshes seen before."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

from converters.resources import mesh_store
from converters.resources.meshes import load_mesh, read_mesh_file

SEEDS = Path(__file__).resolve().parents[1] / "fuzz" / "seeds"
HEAVY = {"trimesh", "scipy", "coacd", "yourdfpy"}
PRIMITIVE = (
    '<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01" '
    'iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial><collision><geometry>'
    '<box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
)


def _convert_imports(robot: Path, out: Path, cache: Path) -> set[str]:
    """Top-level packages `twin convert ROBOT` imports, in a fresh process."""
    env = {**os.environ, "TWIN_CACHE_DIR": str(cache)}
    proc = subprocess.run(
        [
            sys.executable,
            "-X",
            "importtime",
            "-m",
            "twin_cli",
            "convert",
            str(robot),
            "-o",
            str(out),
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    names = re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M)
    return {n.split(".")[0] for n in names}


def test_a_primitive_robot_converts_without_mesh_libraries(tmp_path: Path) -> None:
    robot = tmp_path / "box.urdf"
    robot.write_text(PRIMITIVE)
    imported = _convert_imports(robot, tmp_path / "out", tmp_path / "cache")
    assert not imported & HEAVY, f"imported {sorted(imported & HEAVY)}"


def test_a_mesh_seen_before_is_read_from_the_store(tmp_path: Path) -> None:
    robot = SEEDS / "arm.urdf"
    first = _convert_imports(robot, tmp_path / "a", tmp_path / "cache")
    assert "trimesh" in first, "the first conversion reads the STL with trimesh"
    second = _convert_imports(robot, tmp_path / "b", tmp_path / "cache")
    assert not second & HEAVY, f"warm conversion imported {sorted(second & HEAVY)}"
    assert (tmp_path / "a" / "fuzz_arm.xml").read_bytes() == (
        tmp_path / "b" / "fuzz_arm.xml"
    ).read_bytes(), "the same model from the store"


def test_stored_mesh_equals_the_file(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path))
    path = SEEDS / "cube.stl"
    fresh = read_mesh_file(path, "l")
    load_mesh(path, "l")  # stores it
    stored = mesh_store.load(mesh_store.key_of(path))
    assert stored is not None, "an entry was written"
    assert np.array_equal(stored.vertices, fresh.vertices), "vertices [m]"
    assert np.array_equal(stored.faces, fresh.faces), "faces"
    assert (stored.rgba, stored.textured) == (fresh.rgba, fresh.textured)
