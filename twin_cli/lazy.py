"""Lazy package exports: a package lists its public names, and each loads its module on first use.

Client commands import `twin_cli` and `twin_cli.server` on every call; eager imports there would
pull mujoco, numpy or fastapi into a command that only sends one HTTP request (PEP 562).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_getattr(package: str, where: Mapping[str, str]) -> Callable[[str], Any]:
    """A module `__getattr__` that imports `where[name]` and returns its attribute `name`."""

    def __getattr__(name: str) -> Any:
        if name in where:
            return getattr(importlib.import_module(where[name]), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
