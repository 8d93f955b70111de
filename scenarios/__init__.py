"""Declarative physics scenarios (TOML) run by `twin validate`, and the bundled example robots."""

from __future__ import annotations

from pathlib import Path

SCENARIO_DIR = Path(__file__).resolve().parent
ROBOTS_DIR = SCENARIO_DIR / "robots"
HUMANOID = ROBOTS_DIR / "humanoid.urdf.xacro"

__all__ = ["HUMANOID", "ROBOTS_DIR", "SCENARIO_DIR"]
