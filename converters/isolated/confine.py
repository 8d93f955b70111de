"""Reads confined to named folders, for a conversion asked for by someone who is not the
server's user (a DDS peer's spawn): the server must not read a file on their behalf that they
could not name through the world's own package and model paths.

Python's audit hook sees every `open` (the converters read meshes, height images and included
files through Python); the folders hold for the conversion's own thread only, so a world that
converts for its own user meanwhile reads as before. MuJoCo's C reader is not watched: a
confined conversion never hands it a file (MJCF is refused before it gets here). Files a
sandboxed xacro read are announced as `READ_EVENT`s and held to the same folders.
"""

from __future__ import annotations

import os
import site
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path

from converters.errors import OutsideRootsError
from converters.isolated.bounded_child import READ_EVENT

_ROOTS: ContextVar[tuple[tuple[str, ...], tuple[str, ...]] | None] = ContextVar(
    "converters_read_roots", default=None
)  # (the folders given, all folders allowed)
_WRITE_MODES = ("w", "a", "x", "+")
# What the interpreter and the libraries read for themselves while converting (CPU counts).
_SYSTEM = ("/proc/self/", "/sys/devices/system/cpu/", "/dev/null", "/dev/urandom")
_installed: list[bool] = []


@contextmanager
def confined(roots: Sequence[str], also: Sequence[str] = ()) -> Iterator[None]:
    """Refuse, in this thread (or task) meanwhile, reading any file outside `roots` (besides
    Python's own installation and the folders `also` names, such as a cache), with an
    `OutsideRootsError` naming the file and `roots`: not an OSError, so no reader takes it
    for a broken file and carries on."""
    if not _installed:
        sys.addaudithook(_hook)
        _installed.append(True)
    given = tuple(_folder(r) for r in roots)
    token = _ROOTS.set((given, given + tuple(_folder(f) for f in also) + _own_folders()))
    try:
        yield
    finally:
        _ROOTS.reset(token)


def inside(path: str | os.PathLike, roots: Sequence[str]) -> bool:
    """Whether `path` (links followed) lies in one of `roots`."""
    real = os.path.realpath(path)
    return any(real == r.rstrip(os.sep) or real.startswith(r) for r in map(_folder, roots))


def _hook(event: str, args: tuple) -> None:
    if event not in ("open", READ_EVENT):
        return
    folders = _ROOTS.get()
    if folders is None or not isinstance(args[0], (str, bytes, os.PathLike)):
        return
    mode = args[1] if event == "open" else "r"
    if isinstance(mode, str) and any(m in mode for m in _WRITE_MODES):
        return
    if isinstance(mode, int) and mode & (os.O_WRONLY | os.O_RDWR):
        return
    name = os.fsdecode(args[0])
    if name.startswith(_SYSTEM):
        return
    real = os.path.realpath(name)
    if not any(real.startswith(r) for r in folders[1]):
        raise OutsideRootsError(name, folders[0])


def _folder(path: str | os.PathLike) -> str:
    return os.path.join(os.path.realpath(path), "")


def _own_folders() -> tuple[str, ...]:
    """Python's installation, the site folders and the folder holding `converters` (its code
    is imported lazily while converting)."""
    folders = {sys.prefix, sys.base_prefix, sys.exec_prefix, site.getusersitepackages()}
    folders |= set(site.getsitepackages())
    folders.add(str(Path(__file__).resolve().parents[2]))
    return tuple(_folder(f) for f in folders)
