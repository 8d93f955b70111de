"""Client commands start light: no world command imports mujoco and friends, nor Typer or httpx."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from models import block

from twin_cli.cli.registry import world_commands
from twin_cli.server import runtime
from twin_cli.server.client import Client

HEAVY = ("mujoco", "numpy", "trimesh", "coacd", "fastapi", "uvicorn", "scipy")
# What the fast path leaves out: the CLI framework (Typer, click, rich) and httpx.
FRAMEWORK = ("typer", "click", "rich", "httpx")
WORLD = "lazy"


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


def _client_commands(tmp_path) -> list[list[str]]:
    """Every world command once, in an order that works on one world (stop last)."""
    box = tmp_path / "box.urdf"
    box.write_text(block(size=0.2, name="box"))
    saved = tmp_path / "world.twin"
    return [
        ["spawn", str(box), "-z", "1", "--name", "box"],
        ["list"],
        ["pose", "box"],
        ["pose", "box", "--set", "0", "0", "2", "0", "0", "0"],
        ["joints", "box", "--json"],
        ["push", "box", "--force", "0", "0", "5", "--duration", "0.05"],
        ["gravity", "--moon"],
        ["physics", "--json"],
        ["pause"],
        ["step", "3"],
        ["resume"],
        ["reset", "--time-only"],
        ["stats", "-d", "0.2"],
        ["save", str(saved)],
        ["load", str(saved)],
        ["delete", "box"],
        ["logs", "-n", "3"],
        ["stop"],
    ]


def test_stats_without_a_world_imports_nothing_heavy(tmp_path):
    env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path)}
    proc, modules = _imported(["stats", "-d", "0"], env)
    assert proc.returncode == 2, proc.stderr[-500:]
    assert "An instance of twin is not running." in proc.stderr
    assert not modules & set(HEAVY), f"heavy imports: {sorted(modules & set(HEAVY))}"


def test_the_lazy_import_list_covers_every_world_command(tmp_path):
    listed = {args[0] for args in _client_commands(tmp_path)}
    registered = set(world_commands())
    assert listed == registered, f"not covered: {sorted(registered - listed)}"


def test_every_world_command_against_a_running_world_imports_nothing_heavy(tmp_path, monkeypatch):
    monkeypatch.setenv(runtime.RUNTIME_ENV, str(tmp_path))
    env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path)}
    env.pop("TWIN_WORLD", None)
    server = subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", WORLD],
        env=env,
        stderr=subprocess.DEVNULL,
    )
    client = Client(WORLD)
    try:
        runtime.wait_until(client.paths, client.alive, server, 60.0)
        for args in _client_commands(tmp_path):
            if args[0] == "stop":
                assert client.gravity()["gravity"] == pytest.approx([0.0, 0.0, -1.62])
            proc, modules = _imported([*args, "--world", WORLD], env)
            assert proc.returncode == 0, f"twin {args}: {proc.stderr[-500:]}"
            assert not modules & set(HEAVY), f"twin {args} imported {modules & set(HEAVY)}"
            assert not modules & set(FRAMEWORK), f"twin {args} imported {modules & set(FRAMEWORK)}"
        assert server.wait(timeout=30) == 0, "`twin stop` should end the server"
    finally:
        client.close()
        if server.poll() is None:
            server.terminate()
            server.wait(timeout=20)


def test_view_and_snapshot_import_neither_physics_nor_the_viewer(tmp_path, monkeypatch):
    """`twin view` and `twin snapshot` only ask the server (which hosts and renders)."""
    monkeypatch.setenv(runtime.RUNTIME_ENV, str(tmp_path))
    env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path)}
    env.pop("TWIN_WORLD", None)
    server = subprocess.Popen(
        [sys.executable, "-m", "twin_cli.cli.app", "serve", "--world", WORLD],
        env=env,
        stderr=subprocess.DEVNULL,
    )
    client = Client(WORLD)
    commands = [
        ["view"],
        ["snapshot", str(tmp_path / "w.png"), "--width", "64"],
        ["view", "--stop"],
    ]
    try:
        runtime.wait_until(client.paths, client.alive, server, 60.0)
        for args in commands:
            proc = subprocess.run(
                [
                    sys.executable,
                    "-X",
                    "importtime",
                    "-m",
                    "twin_cli.cli.app",
                    *args,
                    "--world",
                    WORLD,
                ],
                env=env,
                capture_output=True,
                text=True,
                timeout=60,
            )
            assert proc.returncode in (0, 2), f"twin {args}: {proc.stderr[-500:]}"
            names = set(
                re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M)
            )
            heavy = {n for n in names if n.split(".")[0] in HEAVY or n.startswith("twin_cli.view")}
            assert not heavy, f"twin {args} imported {sorted(heavy)}"
            assert "mujoco.studio" not in names
    finally:
        client.close()
        server.terminate()
        server.wait(timeout=20)


def test_topics_echo_and_model_import_no_physics(tmp_path, serve_world):
    """The live look inside only asks the server, which names, samples and poses everything."""
    box = tmp_path / "box.urdf"
    box.write_text(block(size=0.2, name="box"))
    with serve_world(tmp_path / "rt", WORLD) as (client, _):
        client.spawn(str(box), name="box", pose={"z": 1.0})
        env = {**os.environ, runtime.RUNTIME_ENV: str(tmp_path / "rt")}
        env.pop("TWIN_WORLD", None)
        for args in (
            ["topics"],
            ["topics", "echo", "/box/joint_states", "-n", "2"],
            ["model", "box"],
        ):
            proc, modules = _imported([*args, "--world", WORLD], env)
            assert proc.returncode == 0, f"twin {args}: {proc.stderr[-500:]}"
            assert not modules & set(HEAVY), f"twin {args} imported {modules & set(HEAVY)}"
