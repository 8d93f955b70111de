"""The import contracts hold on the tree, and break when a module imports against the flow or
two modules of a package import each other (a circle, at module level or inside a function)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")
PACKAGES = ("twin_cli", "converters", "scenarios")

pytestmark = pytest.mark.skipif(not LINT_IMPORTS.exists(), reason="import-linter not installed")


CYCLES = "no-import-cycles"  # the id of the acyclic-siblings contract in pyproject.toml


def _lint_imports(cwd: Path, contract: str | None = None) -> subprocess.CompletedProcess:
    only = ["--contract", contract] if contract else []
    command = [str(LINT_IMPORTS), "--no-cache", *only]
    return subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=120)


def _copy_tree(tmp_path: Path) -> Path:
    for package in PACKAGES:
        shutil.copytree(ROOT / package, tmp_path / package, ignore=shutil.ignore_patterns("*.pyc"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    return tmp_path


def test_the_tree_keeps_every_contract() -> None:
    proc = _lint_imports(ROOT)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    assert "BROKEN" not in proc.stdout


@pytest.mark.parametrize(
    ("module", "line", "broken"),
    [
        ("twin_cli/world/engine.py", "import twin_cli.server.app", "twin_cli.world.engine ->"),
        ("converters/pipeline.py", "import twin_cli.world", "converters.pipeline ->"),
        ("twin_cli/server/client.py", "import numpy", "twin_cli.server.client -> numpy"),
        ("converters/mjcf/builder.py", "import converters.urdf", "converters.mjcf.builder ->"),
    ],
)
def test_an_import_against_the_flow_breaks_a_contract(
    tmp_path: Path, module: str, line: str, broken: str
) -> None:
    tree = _copy_tree(tmp_path)
    with (tree / module).open("a") as handle:
        handle.write(f"\n{line}  # deliberate violation\n")
    proc = _lint_imports(tree)
    assert proc.returncode != 0, f"`{line}` in {module} kept every contract"
    assert broken in proc.stdout, proc.stdout[-2000:]


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
    proc = _lint_imports(tree, CYCLES)
    assert proc.returncode != 0, f"circle_a <-> circle_b in {dotted} passed the check"
    assert f"No cycles are allowed in {dotted}." in proc.stdout, proc.stdout[-3000:]
    assert "circle_" in proc.stdout, proc.stdout[-3000:]
