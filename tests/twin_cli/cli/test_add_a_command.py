"""Adding a world command as docs/architecture.md says: one module, found by the registry.

A copy of `twin_cli` gets one new file, `cli/world_commands/toy.py`, and nothing else; `twin toy`
then runs on the fast path (no Typer) against a real world, and `twin --help` and
`twin toy --help` list it through Typer. The other two files the docs name are tests (the
lazy-import list and the command's own test), so the command touches three files in all.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from source_trees import changed_files

ROOT = Path(__file__).resolve().parents[3]
TOY = '''"""`twin toy`: the world's gravity along z, a worked example of a world command."""

from __future__ import annotations

from twin_cli.cli.output import Output
from twin_cli.cli.params import JSON, WORLD
from twin_cli.cli.registry import Opt, command
from twin_cli.cli.world_client import connect_world


@command(
    "toy",
    Opt(("--scale",), "scale", "Multiply it by this.", float, 1.0),
    WORLD,
    JSON,
    help="Print the world's gravity along z [m/s^2].",
)
def toy(*, scale: float, world: str, json: bool) -> None:
    with connect_world(world) as c:
        z = c.gravity()["gravity"][2] * scale
    out = Output(json)
    if json:
        out.data({"z": z})
    else:
        out.line(f"{z:g}")
'''
MOON_Z = -1.62  # [m/s^2] the server's `moon` preset, exact as sent back


def _twin(tree: Path, runtime_dir: Path, *args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": f"{tree}{os.pathsep}{ROOT}", "COLUMNS": "200"}
    env.update(TWIN_RUNTIME_DIR=str(runtime_dir))
    env.pop("TWIN_WORLD", None)
    return subprocess.run(
        [sys.executable, "-X", "importtime", "-m", "twin_cli", *args],
        cwd=tree,  # `-m` puts the working directory first on the path
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )


def _imports(proc: subprocess.CompletedProcess) -> set[str]:
    return set(re.findall(r"^import time:\s+\d+ \|\s+\d+ \|\s*([\w.]+)", proc.stderr, re.M))


@pytest.fixture()
def toy_tree(tmp_path: Path) -> Path:
    """A copy of `twin_cli` with the toy command's module added, and only that."""
    tree = tmp_path / "tree"
    shutil.copytree(ROOT / "twin_cli", tree / "twin_cli", ignore=shutil.ignore_patterns("*.pyc"))
    (tree / "twin_cli/cli/world_commands/toy.py").write_text(TOY)
    assert changed_files(ROOT / "twin_cli", tree / "twin_cli") == ["cli/world_commands/toy.py"]
    return tree


def test_a_toy_command_in_one_module_runs_on_the_fast_path(
    toy_tree: Path, tmp_path: Path, serve_world
) -> None:
    runtime_dir = tmp_path / "rt"
    with serve_world(runtime_dir, "default") as (client, _):
        client.set_gravity(preset="moon")
        proc = _twin(toy_tree, runtime_dir, "toy", "--scale", "2")
        assert proc.returncode == 0, proc.stderr[-2000:]
        assert float(proc.stdout) == pytest.approx(2 * MOON_Z, rel=1e-12), proc.stdout
        assert "typer" not in {name.split(".")[0] for name in _imports(proc)}, "not fast path"
        proc = _twin(toy_tree, runtime_dir, "toy", "--json")
        assert proc.returncode == 0 and '"z": -1.62' in proc.stdout, proc.stdout


def test_a_toy_command_in_one_module_has_typer_help_and_usage_errors(
    toy_tree: Path, tmp_path: Path
) -> None:
    listing = _twin(toy_tree, tmp_path, "--help").stdout
    assert re.search(r"logs .*\n.*toy +Print the world's gravity along z", listing), listing
    page = _twin(toy_tree, tmp_path, "toy", "--help")
    assert page.returncode == 0 and "--scale" in page.stdout and "--world" in page.stdout
    bad = _twin(toy_tree, tmp_path, "toy", "--scale", "abc")
    assert bad.returncode == 2 and "Invalid value for '--scale'" in bad.stderr, bad.stderr
    assert not (tmp_path / "default.sock").exists(), "a usage error must not start a world"


def test_a_second_function_under_a_registered_name_is_refused() -> None:
    from twin_cli.cli.registry import DuplicateCommandError, command, world_commands

    pause = world_commands()["pause"].action

    def other_pause(*, world: str) -> None:
        """Would shadow `twin pause`."""

    with pytest.raises(DuplicateCommandError, match=r"`twin pause` is registered twice: by "):
        command("pause", help="Pause.")(other_pause)
    assert world_commands()["pause"].action is pause
