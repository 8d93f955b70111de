"""A large mesh shows progress on a terminal, for `twin convert` and for a served `twin spawn`,
and nothing when stderr is piped.

The terminal is a real pseudo-terminal (`pty`): rich draws its status line only on a terminal.
"""

from __future__ import annotations

import os
import pty
import select
import subprocess
import sys
from pathlib import Path

from tests.big_meshes import write_grid_obj
from tests.cli_world import twin_in, twin_ok

WORLD = "progress"
FACES = 190_000  # trimesh (imported first) reads it in ~1 s, past SHOW_AFTER_S
ROBOT = """<robot name="heavy"><link name="base">
  <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>
  </inertial>
  <visual><geometry><mesh filename="{mesh}"/></geometry></visual>
  <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
</link></robot>"""
BOX = (
    '<robot name="box"><link name="b"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
    'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
)


def on_terminal(args: list[str], env: dict[str, str]) -> tuple[int, str]:
    """Run `twin ARGS` with stderr on a pseudo-terminal; its exit code and what it drew there."""
    leader, follower = pty.openpty()
    process = subprocess.Popen(
        [sys.executable, "-m", "twin_cli", *args],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.DEVNULL,
        stderr=follower,
        env={**env, "TERM": "xterm-256color", "COLUMNS": "200"},
    )
    os.close(follower)
    drawn = bytearray()
    while True:
        ready, _, _ = select.select([leader], [], [], 0.2)
        if not ready:
            if process.poll() is not None:
                break
            continue
        try:
            chunk = os.read(leader, 65536)
        except OSError:  # the terminal closed with the process
            break
        if not chunk:
            break
        drawn += chunk
    os.close(leader)
    return process.wait(timeout=120), drawn.decode(errors="replace")


def _robot(folder: Path) -> tuple[Path, Path]:
    folder.mkdir()
    mesh = folder / "bumps.obj"
    write_grid_obj(mesh, FACES)
    robot = folder / "heavy.urdf"
    robot.write_text(ROBOT.format(mesh=mesh.name))
    return robot, mesh


def test_twin_convert_shows_the_mesh_it_reads_on_a_terminal_only(tmp_path, monkeypatch):
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    robot, mesh = _robot(tmp_path / "robot")
    code, drawn = on_terminal(["convert", str(robot), "-o", str(tmp_path / "a")], dict(os.environ))
    assert code == 0, drawn
    assert f"reading mesh {mesh}" in drawn and "MB)" in drawn, drawn[-2000:]
    # The same conversion again, piped: the mesh store now has it, but the text must not
    # appear in any case; so convert a second, fresh mesh.
    robot, mesh = _robot(tmp_path / "robot2")
    piped = subprocess.run(
        [sys.executable, "-m", "twin_cli", "convert", str(robot), "-o", str(tmp_path / "b")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert piped.returncode == 0, piped.stderr
    assert "reading mesh" not in piped.stderr + piped.stdout, piped.stderr


def test_twin_spawn_shows_the_worlds_conversion_stage_on_a_terminal_only(tmp_path, monkeypatch):
    runtime = tmp_path / "rt"
    runtime.mkdir(mode=0o700)
    monkeypatch.setenv("TWIN_CACHE_DIR", str(tmp_path / "cache"))
    twin_ok(runtime, WORLD, "spawn", "--xml", BOX, "--name", "box")
    try:
        robot, mesh = _robot(tmp_path / "robot")
        env = {**os.environ, "TWIN_RUNTIME_DIR": str(runtime)}
        env.pop("TWIN_WORLD", None)
        code, drawn = on_terminal(["spawn", str(robot), "--name", "a", "--world", WORLD], env)
        assert code == 0, drawn
        assert f"reading mesh {mesh}" in drawn, drawn[-2000:]
        robot, mesh = _robot(tmp_path / "robot2")
        piped = twin_in(runtime, WORLD, "spawn", str(robot), "--name", "b")
        assert piped.returncode == 0, piped.stderr
        assert "reading mesh" not in piped.stderr + piped.stdout, piped.stderr
    finally:
        twin_in(runtime, WORLD, "stop")
