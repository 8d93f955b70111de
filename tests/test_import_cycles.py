"""No import circles inside twin_cli or converters; a circle added to a copy breaks the check."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")
PACKAGES = ("twin_cli", "converters", "scenarios")
CONTRACT = "no-import-cycles"  # the contract's id in pyproject.toml, which `make lint` checks

pytestmark = pytest.mark.skipif(not LINT_IMPORTS.exists(), reason="import-linter not installed")


def _check_cycles(cwd: Path) -> subprocess.CompletedProcess:
    command = [str(LINT_IMPORTS), "--no-cache", "--contract", CONTRACT]
    return subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=120)


def _copy_tree(tmp_path: Path) -> Path:
    for package in PACKAGES:
        shutil.copytree(ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("*.pyc"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    return tmp_path


def test_the_tree_has_no_import_circle() -> None:
    proc = _check_cycles(ROOT)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]


@pytest.mark.parametrize(
    ("package", "back_import"),
    [
        ("twin_cli/record", "from twin_cli.record import circle_a\n"),
        ("converters/resources", "def load():\n    from converters.resources import circle_a\n"),
    ],
    ids=["module-level", "inside-a-function"],
)
def test_a_circle_breaks_the_check(tmp_path: Path, package: str, back_import: str) -> None:
    tree = _copy_tree(tmp_path)
    dotted = package.replace("/", ".")
    (tree / package / "circle_a.py").write_text(f"from {dotted} import circle_b\n")
    (tree / package / "circle_b.py").write_text(back_import)
    proc = _check_cycles(tree)
    assert proc.returncode != 0, f"circle_a <-> circle_b in {dotted} passed the check"
    assert f"No cycles are allowed in {dotted}." in proc.stdout, proc.stdout[-3000:]
    assert "circle_" in proc.stdout, proc.stdout[-3000:]
