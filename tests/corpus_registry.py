"""The corpus of real robot packages (../shared/corpus): where it is and what robots.toml lists."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import tomllib

REPO_ROOT = Path(__file__).resolve().parent.parent
CORPUS_ROOT = REPO_ROOT.parent / "shared" / "corpus"
PACKAGES_ROOT = CORPUS_ROOT / "packages"


def corpus_robots() -> list[dict[str, Any]]:
    """The `[[robot]]` entries of robots.toml (empty when the corpus is absent)."""
    manifest = CORPUS_ROOT / "robots.toml"
    if not manifest.is_file():
        return []
    return tomllib.loads(manifest.read_text())["robot"]


CORPUS = {robot["id"]: robot for robot in corpus_robots()}
# Robots whose upstream inertias are non-physical: they must fail, then convert with repair.
NON_PHYSICAL_INERTIA = ("abb_irb2400_12_155", "anymal_c", "hyq")


def package_paths(robot: dict[str, Any]) -> dict[str, Path]:
    """`--package NAME=PATH` for every package a corpus robot lists."""
    return {name: PACKAGES_ROOT / name for name in robot["packages"]}
