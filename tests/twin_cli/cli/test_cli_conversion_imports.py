"""`twin convert` and `twin validate` import mesh libraries only when a mesh needs them.

An import-set test, not a timing test: trimesh (with scipy) costs 0.8-1 s to import, CoACD runs
only in its worker process, and matplotlib only for `twin validate --plots`.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from converters.mjcf.writer import stl_bytes
from scenarios import HUMANOID

MESH_LIBRARIES = {"trimesh", "scipy", "coacd", "yourdfpy"}
BOX = '<box size="0.1 0.1 0.1"/>'
# A visual STL mesh on a box-collision link: the mesh is read, never decomposed.
STL_VISUAL = """<robot name="stl_visual"><link name="base">
<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
</inertial><visual><geometry><mesh filename="tet.stl" scale="0.5 0.5 0.5"/></geometry></visual>
<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>"""


def twin_imports(
    args: list[str], cache: Path, *, full: bool = False, gl: str | None = None
) -> set[str]:
    """Top-level packages (`full`: modules) a fresh `twin ARGS` imports (with an empty twin
    cache at `cache`; `gl`: MUJOCO_GL, None: unset)."""
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    env.update({"TWIN_CACHE_DIR": str(cache)}, **({"MUJOCO_GL": gl} if gl else {}))
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "twin_cli", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, f"twin {args}: {proc.stderr[-2000:]}"
    names = re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M)
    return set(names) if full else {name.split(".")[0] for name in names}


def test_convert_of_a_binary_stl_visual_imports_no_mesh_library(tmp_path: Path) -> None:
    vertices = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    (tmp_path / "tet.stl").write_bytes(stl_bytes(vertices, faces))
    robot = tmp_path / "robot.urdf"
    robot.write_text(STL_VISUAL)
    imported = twin_imports(["convert", str(robot), "-o", str(tmp_path / "out")], tmp_path / "c")
    assert not imported & MESH_LIBRARIES, f"imported {sorted(imported & MESH_LIBRARIES)}"
    assert (tmp_path / "out" / "assets").is_dir(), "the visual mesh was written"


@pytest.mark.parametrize("command", ["convert", "inspect"])
@pytest.mark.parametrize("gl", [None, "egl"])
def test_convert_imports_no_gl_backend_and_no_world_client(
    tmp_path: Path, command: str, gl: str | None
) -> None:
    """A conversion never renders or talks to a world: `import mujoco` without its GL backend
    (glfw: ~60 ms; EGL's loads PyOpenGL), and the world commands' client (the spawn request with
    hashlib, the server connection) only when one runs; whatever MUJOCO_GL says."""
    robot = tmp_path / "box.urdf"
    robot.write_text(STL_VISUAL.replace('<mesh filename="tet.stl" scale="0.5 0.5 0.5"/>', BOX))
    args = [command, str(robot)] + (["-o", str(tmp_path / "out")] if command == "convert" else [])
    imported = twin_imports(args, tmp_path / "c", full=True, gl=gl)
    assert "mujoco" in imported
    unwanted = {"glfw", "mujoco.glfw", "mujoco.egl", "OpenGL"}
    unwanted |= {"twin_cli.spawn_request", "twin_cli.server.connection"}
    assert not imported & unwanted, f"imported {sorted(imported & unwanted)}"


def test_the_gl_less_import_puts_mujoco_gl_back() -> None:
    """Processes a command starts later (a world server) see the user's MUJOCO_GL."""
    script = (
        "import os, sys\n"
        "from twin_cli.cli.commands.convert import import_mujoco_without_gl\n"
        "import_mujoco_without_gl()\n"
        "print(os.environ.get('MUJOCO_GL'), 'mujoco' in sys.modules, 'glfw' in sys.modules)\n"
    )
    for given, expected in (("egl", "egl"), (None, "None")):
        env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
        env.update({"MUJOCO_GL": given} if given else {})
        proc = subprocess.run(
            [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120
        )
        assert proc.stdout.split() == [expected, "True", "False"], proc.stderr


def test_validate_of_the_primitive_humanoid_imports_no_mesh_or_plot_library(
    tmp_path: Path,
) -> None:
    imported = twin_imports(["validate", str(HUMANOID), "--json"], tmp_path / "cache")
    heavy = MESH_LIBRARIES | {"matplotlib"}
    assert not imported & heavy, f"imported {sorted(imported & heavy)}"
