"""`make lint` refuses code that reaches into another object's privates (ruff's SLF rule).

The world's state lives behind `World`'s methods; a server route or a consumer that read
`world._state` would bypass its lock and its checks. Tests and benchmarks may look inside.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
RUFF = Path(sys.executable).with_name("ruff")
PEEK = "def entities(world):\n    return world._state.entities\n"

pytestmark = pytest.mark.skipif(not RUFF.exists(), reason="ruff not installed")


def _ruff(tmp_path: Path, relative: str) -> subprocess.CompletedProcess:
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    target = tmp_path / relative
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(PEEK)
    command = [str(RUFF), "check", "--no-cache", relative]
    return subprocess.run(command, cwd=tmp_path, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("relative", ["twin_cli/server/peek.py", "twin_cli/record/peek.py"])
def test_a_private_world_attribute_outside_the_world_fails_lint(tmp_path, relative) -> None:
    proc = _ruff(tmp_path, relative)
    assert proc.returncode == 1 and "SLF001" in proc.stdout, proc.stdout + proc.stderr


def test_tests_may_look_inside(tmp_path) -> None:
    proc = _ruff(tmp_path, "tests/twin_cli/test_peek.py")
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_tree_reaches_into_no_private(tmp_path) -> None:
    command = [str(RUFF), "check", "--no-cache", "--select", "SLF001", "twin_cli", "converters"]
    proc = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stdout[-3000:]
