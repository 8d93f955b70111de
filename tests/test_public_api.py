"""Each package's `__all__` names exist, and importing a package stays free of heavy modules."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize("package", ["converters", "twin_cli", "scenarios"])
def test_every_name_in_all_resolves(package: str) -> None:
    module = __import__(package)
    missing = [name for name in module.__all__ if getattr(module, name, None) is None]
    assert missing == [], f"{package}.__all__ names that do not resolve: {missing}"


@pytest.mark.parametrize("package", ["converters", "twin_cli"])
def test_importing_a_package_imports_no_physics(package: str) -> None:
    heavy = "('mujoco', 'numpy', 'trimesh', 'coacd')"
    code = f"import sys, {package}; print(sorted(m for m in {heavy} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", f"`import {package}` loaded {out.stdout.strip()}"
