"""On-disk cache of collision parts, keyed by mesh bytes, scale, parameters and CoACD version.

Entries live in `<cache root>/collision/<sha256>.npz`; the root is the user cache directory
(platformdirs) or `$TWIN_CACHE_DIR`. A write goes to a private temporary file in the same
directory and is renamed into place (`os.replace` is atomic on POSIX and Windows), so a reader
never sees half an entry and two processes storing the same key at once both succeed; the
last rename wins and both wrote the same bytes.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ENV_CACHE_DIR = "TWIN_CACHE_DIR"
SUBDIR = "collision"
SUFFIX = ".npz"
# Bump when the entry layout or the meaning of a stored result changes.
FORMAT_VERSION = 1


@dataclass(frozen=True)
class CacheInfo:
    """What `twin cache info` shows: `path` of the collision cache, entries and bytes on disk."""

    path: Path
    entries: int
    bytes: int


@dataclass(frozen=True)
class CachedResult:
    """One stored result: the parts as (vertices [m], faces) pairs and a JSON-able `meta` dict."""

    parts: list[tuple[np.ndarray, np.ndarray]]
    meta: dict[str, Any]


def pack_parts(parts: list[tuple[np.ndarray, np.ndarray]]) -> dict[str, np.ndarray]:
    """Parts as .npz arrays `v0, f0, v1, f1, ...` (float64 vertices, int32 faces); the one
    layout shared by cache entries and CoACD worker results."""
    arrays: dict[str, np.ndarray] = {}
    for i, (vertices, faces) in enumerate(parts):
        arrays[f"v{i}"] = np.asarray(vertices, np.float64)
        arrays[f"f{i}"] = np.asarray(faces, np.int32)
    return arrays


def unpack_parts(data: Mapping[str, np.ndarray], count: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The first `count` parts of an open .npz written from `pack_parts`."""
    return [(data[f"v{i}"], data[f"f{i}"]) for i in range(count)]


def cache_root() -> Path:
    """twin's cache directory: `$TWIN_CACHE_DIR` if set, else the per-user cache dir."""
    override = os.environ.get(ENV_CACHE_DIR)
    if override:
        return Path(override).expanduser()
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("twin", appauthor=False))


def collision_dir() -> Path:
    """Directory that holds the collision entries (not created here)."""
    return cache_root() / SUBDIR


def coacd_version() -> str:
    """The installed CoACD version, part of every key (its results change between versions)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("coacd")
    except PackageNotFoundError:
        return "absent"


def entry_key(
    vertices: np.ndarray, faces: np.ndarray, facts: dict[str, Any], *, version: str | None = None
) -> str:
    """The key of one mesh under one set of choices.

    Args:
        vertices: (N, 3) float64 [m], the mesh after scaling (so the key covers mesh bytes and
            scale even for formats whose file bytes do not change with `scale`).
        faces: (M, 3) vertex indices.
        facts: everything else the result depends on (mode, parameters, scale, hull cap);
            must be JSON-serialisable.
        version: the CoACD version to key on (default: the installed one).

    Returns:
        A hex SHA-256 digest.
    """
    digest = hashlib.sha256()
    header = {"format": FORMAT_VERSION, "coacd": version or coacd_version(), **facts}
    digest.update(json.dumps(header, sort_keys=True).encode())
    digest.update(np.ascontiguousarray(vertices, dtype=np.float64).tobytes())
    digest.update(np.ascontiguousarray(faces, dtype=np.int64).tobytes())
    return digest.hexdigest()


def load(key: str) -> CachedResult | None:
    """The stored result for `key`, or None when absent or unreadable (a damaged entry is
    removed so the next conversion rewrites it)."""
    path = collision_dir() / f"{key}{SUFFIX}"
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            parts = unpack_parts(data, int(meta["n_parts"]))
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, EOFError):
        path.unlink(missing_ok=True)
        return None
    return CachedResult(parts=parts, meta=meta)


def store(key: str, parts: list[tuple[np.ndarray, np.ndarray]], meta: dict[str, Any]) -> Path:
    """Write one entry atomically and return its path.

    Raises:
        OSError: the cache directory cannot be created or written (callers report and go on).
    """
    directory = collision_dir()
    directory.mkdir(parents=True, exist_ok=True)
    arrays = pack_parts(parts)
    arrays["meta"] = np.array(json.dumps({**meta, "n_parts": len(parts)}))
    handle, tmp = tempfile.mkstemp(prefix=f".{key[:16]}.", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(handle, "wb") as stream:
            np.savez(stream, allow_pickle=False, **arrays)  # numbers and text: no pickles
            stream.flush()
            os.fsync(stream.fileno())
        final = directory / f"{key}{SUFFIX}"
        os.replace(tmp, final)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return final


def info() -> CacheInfo:
    """Location, entry count and size of the collision cache."""
    directory = collision_dir()
    files = list(directory.glob(f"*{SUFFIX}")) if directory.is_dir() else []
    size = 0
    for path in files:
        try:
            size += path.stat().st_size
        except FileNotFoundError:  # removed by another process meanwhile
            continue
    return CacheInfo(path=directory, entries=len(files), bytes=size)


def clear() -> int:
    """Remove every collision entry (and stale temporary files); return how many entries went."""
    directory = collision_dir()
    if not directory.is_dir():
        return 0
    removed = 0
    for path in directory.iterdir():
        if path.suffix in (SUFFIX, ".tmp") and path.is_file():
            path.unlink(missing_ok=True)
            removed += path.suffix == SUFFIX
    return removed
