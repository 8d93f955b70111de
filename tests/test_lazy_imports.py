"""Client commands start light: `twin stats` and `twin gravity` never import mujoco and friends."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from twin_cli.server import runtime
from twin_cli.server.client import Client

HEAVY = ("mujoco", "numpy", "trimesh", "coacd", "fastapi", "uvicorn", "scipy")


def _imported(args: list[str], env: dict[str, str]) -> tuple[subprocess.CompletedProcess, set]:
    """Run `twin ARGS` with -X importtime; return the process and its top-level imports."""
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "twin_cli.cli.app", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    names = set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M))
    return proc, {n.split(".")[0] for n in names}


def test_stats_without_a_world_imports_nothing_heavy(tmp_path):
    env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path)}
    proc, modules = _imported(["stats", "-d", "0"], env)
    assert proc.returncode == 1, proc.stderr[-500:]
    assert "An instance of twin is not running." in proc.stderr
    assert not modules & set(HEAVY), f"heavy imports: {sorted(modules & set(HEAVY))}"


def test_client_commands_against_a_running_world_import_nothing_heavy(tmp_path, monkeypatch):
    monkeypatch.setenv(runtime.RUNTIME_ENV, str(tmp_path))
    env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path)}
    server = subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", "lazy"],
        env=env,
        stderr=subprocess.DEVNULL,
    )
    client = Client("lazy")
    try:
        runtime.wait_until(client.paths, client.alive, server, 60.0)
        for args in (["gravity", "--moon"], ["stats", "-d", "0.2"], ["list"]):
            proc, modules = _imported([*args, "--world", "lazy"], env)
            assert proc.returncode == 0, f"twin {args}: {proc.stderr[-500:]}"
            assert not modules & set(HEAVY), f"twin {args} imported {modules & set(HEAVY)}"
        assert client.gravity()["gravity"] == pytest.approx([0.0, 0.0, -1.62])
    finally:
        client.close()
        server.terminate()
        server.wait(timeout=20)
