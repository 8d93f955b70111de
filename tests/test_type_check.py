"""`make lint` type-checks converters/ and twin_cli/world/ (pyright, basic): a type error there
fails it (that the tree has none, `make lint` itself checks)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PYRIGHT = Path(sys.executable).with_name("pyright")
ENV = {**os.environ, "PYRIGHT_PYTHON_IGNORE_WARNINGS": "1"}  # no version check over the network

pytestmark = pytest.mark.skipif(not PYRIGHT.exists(), reason="pyright not installed")


def _pyright(project: Path, *paths: str) -> subprocess.CompletedProcess:
    command = [str(PYRIGHT), "-p", str(project / "pyproject.toml"), *paths]
    return subprocess.run(
        command, cwd=project, capture_output=True, text=True, timeout=300, env=ENV
    )


@pytest.mark.parametrize("package", ["converters", "twin_cli/world"])
def test_a_type_error_in_a_checked_package_fails(tmp_path: Path, package: str) -> None:
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    (tmp_path / ".venv").symlink_to(ROOT / ".venv")
    module = tmp_path / package / "typo.py"
    module.parent.mkdir(parents=True)
    module.write_text("def mass() -> float:\n    return 'heavy'\n")
    done = _pyright(tmp_path, f"{package}/typo.py")
    assert done.returncode != 0 and "typo.py:2" in done.stdout, done.stdout[-2000:]
