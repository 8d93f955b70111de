"""Each package's `__all__` names exist, and importing a package stays free of heavy modules."""

from __future__ import annotations

import subprocess
import sys

import pytest

PACKAGES = [
    "converters",
    "converters.collision",
    "converters.description",
    "converters.gazebo",
    "converters.isolated",
    "converters.mjcf",
    "converters.resources",
    "converters.sdf",
    "converters.serving",
    "converters.urdf",
    "scenarios",
    "twin_cli",
    "twin_cli.cli",
    "twin_cli.live",
    "twin_cli.record",
    "twin_cli.ros",
    "twin_cli.sensors",
    "twin_cli.control",
    "twin_cli.files",
    "twin_cli.server",
    "twin_cli.validate",
    "twin_cli.view",
    "twin_cli.world",
]


@pytest.mark.parametrize("package", PACKAGES)
def test_every_name_in_all_resolves(package: str) -> None:
    import importlib

    module = importlib.import_module(package)
    missing = [name for name in module.__all__ if getattr(module, name, None) is None]
    assert missing == [], f"{package}.__all__ names that do not resolve: {missing}"


@pytest.mark.parametrize("package", ["converters", "twin_cli"])
def test_importing_a_package_imports_no_physics(package: str) -> None:
    heavy = "('mujoco', 'numpy', 'trimesh', 'coacd')"
    code = f"import sys, {package}; print(sorted(m for m in {heavy} if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", f"`import {package}` loaded {out.stdout.strip()}"


def test_the_list_covers_every_package() -> None:
    """A new package joins PACKAGES (so its `__all__` is checked); packages whose modules a
    registry finds by scanning (commands, sensor kinds) are exempt."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    found = {
        ".".join(init.parent.relative_to(root).parts)
        for top in ("converters", "twin_cli", "scenarios")
        for init in (root / top).rglob("__init__.py")
    }
    exempt = {"twin_cli.cli.commands", "twin_cli.cli.world_commands", "twin_cli.validate.checks"}
    exempt.add("scenarios.robots")
    exempt |= {"converters.gazebo.sensor_kinds", "twin_cli.sensors.kinds"}
    exempt.add("twin_cli.record.sensor_kinds")
    assert sorted(found - exempt - set(PACKAGES)) == [], "packages missing from PACKAGES"
