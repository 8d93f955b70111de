"""Where a model cannot be written, `twin convert` says so (exit 2), and a killed conversion's
half-written folder does not stay beside the target."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from models import block, write_urdf

from converters import convert
from converters.mjcf.writer import write_model

DEAD_PID = 2**22 + 12345  # above Linux's pid_max (4 194 304): no process has it


def test_a_read_only_folder_is_exit_2_naming_it(tmp_path: Path) -> None:
    """In a private mount namespace (nothing leaks to the machine), on a read-only tmpfs."""
    if shutil.which("unshare") is None or os.geteuid() != 0:
        pytest.skip("needs root and unshare(1) to mount a read-only tmpfs")
    urdf = write_urdf(tmp_path, block(size=0.2, name="box"), "box.urdf")
    mount = tmp_path / "ro"
    mount.mkdir()
    twin = f"{sys.executable} -m twin_cli.cli.app"
    script = f"mount -t tmpfs -o ro,size=1m tmpfs {mount} && {twin} convert {urdf} -o {mount}/out"
    done = subprocess.run(
        ["unshare", "-m", "sh", "-c", script], capture_output=True, text=True, timeout=120
    )
    if "mount:" in done.stderr:
        pytest.skip(f"this machine cannot mount a tmpfs: {done.stderr.strip()}")
    assert done.returncode == 2, done.stderr
    assert f"{mount}/out: cannot write the model there (Read-only file system)" in done.stderr
    assert "Traceback" not in done.stderr and "internal error" not in done.stderr


def test_a_killed_writers_staging_folder_is_removed_and_a_live_ones_kept(tmp_path: Path) -> None:
    spec, report = convert(write_urdf(tmp_path, block(size=0.2, name="box"), "box.urdf"))
    out = tmp_path / "out"
    dead = tmp_path / f".out.{DEAD_PID}.abc12_yz"
    dead_old = tmp_path / f".out.{DEAD_PID}.old.k3j9x0ab"
    live = tmp_path / f".out.{os.getppid()}.def45678"
    users = tmp_path / f".out.{DEAD_PID}.bak"  # not a name twin makes: someone's own folder
    for folder in (dead, dead_old, live, users):
        folder.mkdir()
        (folder / "box.xml").write_text("half")
    write_model(spec, report, out)
    assert not dead.exists() and not dead_old.exists(), "a killed conversion's folder stays"
    assert live.exists(), "a running conversion's staging folder was removed"
    assert users.exists(), "a folder twin did not make was removed"
    assert (out / "scene.xml").is_file()
