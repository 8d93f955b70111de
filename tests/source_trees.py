"""Copies of the source tree that a test changes, and what it changed (the "add a command" and
"add a sensor" guides are checked by counting the files a new one touches)."""

from __future__ import annotations

import filecmp
from pathlib import Path


def changed_files(left: Path, right: Path) -> list[str]:
    """Files added, removed or different between two trees (caches left out)."""
    compared = filecmp.dircmp(left, right, ignore=["__pycache__"])
    found = [*compared.left_only, *compared.right_only, *compared.diff_files]
    for sub in compared.common_dirs:
        found += [f"{sub}/{name}" for name in changed_files(left / sub, right / sub)]
    return found
