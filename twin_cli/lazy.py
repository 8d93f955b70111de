"""Lazy package exports: a package lists its public names, and each loads its module on first use.

Client commands import `twin_cli` and `twin_cli.server` on every call; eager imports there would
pull mujoco, numpy or fastapi into a command that only sends one HTTP request (PEP 562).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Mapping
from types import ModuleType
from typing import Any


def lazy_getattr(package: str, where: Mapping[str, str]) -> Callable[[str], Any]:
    """A module `__getattr__` that imports `where[name]` and returns its attribute `name`."""

    def __getattr__(name: str) -> Any:
        if name in where:
            return getattr(importlib.import_module(where[name]), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


def import_modules(package: str) -> ModuleType:
    """Imports every module of `package`, alphabetically, and returns the package: a registry
    whose entries register themselves where they are written (commands, sensor kinds) finds
    them this way, so no list names them."""
    found = importlib.import_module(package)
    for module in pkgutil.iter_modules(found.__path__):
        importlib.import_module(f"{package}.{module.name}")
    return found
