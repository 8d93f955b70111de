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
import sysconfig
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
# What the libraries may read for themselves while converting (CPU counts), as real paths:
# never `/proc/self/`, whose `root` and `cwd` links lead anywhere.
_SYSTEM_FILES = ("/dev/null", "/dev/urandom")
_SYSTEM_FOLDERS = ("/sys/devices/system/cpu/",)
_installed: list[bool] = []


@contextmanager
def confined(roots: Sequence[str], also: Sequence[str] = ()) -> Iterator[None]:
    """Refuse, in this thread (or task) meanwhile, reading any file outside `roots` (besides
    Python's standard library and site folders, the `converters` package and the folders
    `also` names, such as a cache), with an `OutsideRootsError` naming the file and `roots`:
    not an OSError, so no reader takes it for a broken file and carries on. Writes are not
    watched: a conversion writes only its own cache, at paths no request names."""
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
    """Raise `OutsideRootsError` for a read outside the current thread's folders; links and
    `..` are resolved before the comparison."""
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
    real = os.path.realpath(name)
    if real in _SYSTEM_FILES or real.startswith(_SYSTEM_FOLDERS):
        return
    if not any(real.startswith(r) for r in folders[1]):
        raise OutsideRootsError(name, folders[0])


def _folder(path: str | os.PathLike) -> str:
    return os.path.join(os.path.realpath(path), "")


def _own_folders() -> tuple[str, ...]:
    """Where the code a conversion imports lazily lives: Python's standard library, the site
    folders and the `converters` package itself (not the folder above it, which in a checkout
    is the whole repository)."""
    paths = sysconfig.get_paths()
    folders = {paths[k] for k in ("stdlib", "platstdlib", "purelib", "platlib") if k in paths}
    folders |= set(site.getsitepackages()) | {site.getusersitepackages()}
    folders.add(str(Path(__file__).resolve().parents[1]))
    return tuple(_folder(f) for f in folders)
