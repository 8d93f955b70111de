"""The server's cache of conversions: spawning a file again costs only the attach.

A conversion is keyed by the file, the xacro arguments, the package paths and the environment
variables that steer package lookup; it stays valid while every file the converter *read* has the
same content. Which files those are is observed, not guessed: Python's `open` audit event
(`sys.addaudithook`) is recorded on the converting thread, so xacro includes, `package.xml`
lookups and meshes all count, whatever reader opened them. Files opened for writing (the
converter's own on-disk caches) are not dependencies.

A content digest is memoised by (path, size, mtime, inode), so a hit re-reads nothing unless a
file changed on disk. The cached spec is never handed out: each hit gets a copy, because the
world's attach step edits the child spec it is given.
"""

from __future__ import annotations

import hashlib
import os
import sys
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

from converters.isolated.bounded_child import READ_EVENT
from twin_cli.files.package_env import PACKAGE_ENVS
from twin_cli.spawn_request import SpawnRequest
from twin_cli.world.values import hull_stand_ins

if TYPE_CHECKING:
    import mujoco

    from twin_cli.world.spawn import LoadedSource

MAX_ENTRIES = 32  # conversions kept (a booster_t1 spec holds ~8 MB of mesh arrays)
_WRITE_MODES = ("w", "a", "x", "+")
_CODE_SUFFIXES = (".py", ".pyc", ".so", ".zip", ".pth")  # imports during a conversion: not data
_CODE_DIRS = tuple({sys.prefix, sys.base_prefix, sys.exec_prefix})

_local = threading.local()
_hook_lock = threading.Lock()
_hook_installed = False


def _audit(event: str, args: tuple) -> None:
    """Records files opened for reading on a thread that is recording (see `recording`), and
    those a child process read for it (xacro's, announced as `converters.read`)."""
    if event not in ("open", READ_EVENT):
        return
    files = getattr(_local, "files", None)
    if files is None:
        return
    if event == READ_EVENT:
        files.add(os.fsdecode(args[0]))
        return
    path, mode = args[0], args[1]
    if not isinstance(path, (str, bytes, os.PathLike)):
        return  # an fd
    if isinstance(mode, str) and any(m in mode for m in _WRITE_MODES):
        return
    if isinstance(mode, int) and mode & (os.O_WRONLY | os.O_RDWR):
        return
    name = os.path.abspath(os.fsdecode(path))
    if not name.endswith(_CODE_SUFFIXES) and not name.startswith(_CODE_DIRS):
        files.add(name)


@contextmanager
def recording() -> Iterator[set[str]]:
    """Collects the absolute paths of files opened for reading by this thread meanwhile."""
    global _hook_installed
    with _hook_lock:
        if not _hook_installed:
            sys.addaudithook(_audit)
            _hook_installed = True
    previous = getattr(_local, "files", None)
    _local.files = files = set()
    try:
        yield files
    finally:
        _local.files = previous
        if previous is not None:
            previous.update(files)


_digests: dict[tuple, str] = {}


def file_digest(path: str) -> str | None:
    """BLAKE2 digest of the file's content (None if it is gone), memoised by its stat."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    if not os.path.isfile(path):
        return "<not a file>"
    stamp = (path, st.st_size, st.st_mtime_ns, st.st_ino)
    if stamp not in _digests:
        digest = hashlib.blake2b(digest_size=20)
        with open(path, "rb") as handle:  # not recorded: no recording runs on this thread here
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
        _digests[stamp] = digest.hexdigest()
    return _digests[stamp]


def cache_key(path: Path, request: SpawnRequest, env: dict[str, str] | None) -> tuple:
    """What, besides file contents, decides a conversion's result (`env`: the environment the
    conversion resolves packages in, None: this process's own)."""
    lookup = os.environ if env is None else env
    return (
        str(path),
        tuple(sorted(request.args.items())),
        tuple(sorted(request.package_paths.items())),
        tuple(lookup.get(name, "") for name in PACKAGE_ENVS),
        request.repair_inertia,
        request.strict,
        request.fixed_base,
        request.coacd_cpu_limit,
        request.read_roots,
    )


@dataclass(frozen=True)
class _Entry:
    loaded: LoadedSource  # with the pristine spec
    files: tuple[tuple[str, str | None], ...]  # (path, digest) of every file read


def mesh_keys(spec: mujoco.MjSpec, conversion: tuple) -> dict[str, str]:
    """Mesh name → a digest of the conversion (key and files read) and the name: two meshes
    with the same key come from the same files through the same conversion, so they are equal."""
    base = hashlib.blake2b(repr(conversion).encode(), digest_size=16).hexdigest()
    return {
        m.name: hashlib.blake2b(f"{base}/{m.name}".encode(), digest_size=12).hexdigest()
        for m in spec.meshes
        if m.name
    }


def deferred_keys(loaded: LoadedSource) -> dict[str, str] | None:
    """Mesh keys for a conversion whose hulls stand in for decompositions not run yet: apart
    from the finished conversion's (same files, other meshes), equal for the same stand-ins."""
    from twin_cli.world.values import deferred_meshes

    if loaded.mesh_keys is None:
        return None
    salt = repr(deferred_meshes(loaded.report))
    return {
        name: hashlib.blake2b(f"{key}/deferred/{salt}".encode(), digest_size=12).hexdigest()
        for name, key in loaded.mesh_keys.items()
    }


class ConversionCache:
    """Conversions by key, valid while their files' contents are unchanged (LRU, thread-safe)."""

    def __init__(self, max_entries: int = MAX_ENTRIES) -> None:
        self._entries: OrderedDict[tuple, _Entry] = OrderedDict()
        self._lock = threading.Lock()
        self._max = max_entries
        self.hits = 0
        self.misses = 0

    def load(self, key: tuple, convert: Callable[[], LoadedSource]) -> LoadedSource:
        """The cached result for `key` (a copy, with `cached=True`), else `convert()`'s, stored.

        Errors `convert` raises are not cached, nor a conversion in which a convex hull stands
        in for a decomposition that did not finish: the next spawn tries CoACD again.
        """
        with self._lock:
            entry = self._entries.get(key)
        if entry is not None and all(file_digest(p) == d for p, d in entry.files):
            with self._lock:
                self._entries.move_to_end(key)
                self.hits += 1
            return replace(entry.loaded, spec=entry.loaded.spec.copy(), cached=True)
        with recording() as files:
            loaded = convert()
        read = tuple((p, file_digest(p)) for p in sorted(files))
        loaded = replace(loaded, mesh_keys=mesh_keys(loaded.spec, (key, read)))
        if hull_stand_ins(loaded.report):
            return loaded
        entry = _Entry(replace(loaded, spec=loaded.spec.copy()), read)
        with self._lock:
            self.misses += 1
            self._entries[key] = entry
            self._entries.move_to_end(key)
            while len(self._entries) > self._max:
                self._entries.popitem(last=False)
        return loaded

    def files_of(self, key: tuple) -> list[str]:
        """The files a cached conversion depends on (empty when not cached)."""
        with self._lock:
            entry = self._entries.get(key)
        return [p for p, _ in entry.files] if entry else []

    def clear(self) -> None:
        with self._lock:
            self._entries.clear()


CACHE = ConversionCache()
