"""On-disk store of loaded meshes, keyed by the file's bytes: a warm conversion reads no mesh
format (and imports no trimesh, ~0.8 s with scipy).

ur5e's seven DAE and seven STL files took 1.4 s to load on every conversion, although only
their collision decompositions were cached. An entry holds what `load_mesh` returns (vertices,
faces, the file's main colour, whether it is textured), written atomically next to the
collision cache; a damaged entry is removed and the file loaded again.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from converters.resources.mesh_data import MeshData

SUBDIR = "meshes"
# Bump when what load_mesh returns for the same bytes changes (units, merging, colours).
FORMAT_VERSION = 1


def store_dir() -> Path:
    from converters.collision.cache import cache_root

    return cache_root() / SUBDIR


def key_of(path: Path) -> str:
    """SHA-256 of the file's bytes, the format version and the loader's (trimesh's) version."""
    loader = loader_version()
    digest = hashlib.sha256(f"{FORMAT_VERSION} {loader} {path.suffix.lower()}".encode())
    digest.update(path.read_bytes())
    return digest.hexdigest()


@functools.cache
def loader_version() -> str:
    """trimesh's version, read once per process (package metadata takes ~50 ms to search)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("trimesh")
    except PackageNotFoundError:
        return "absent"


def load(key: str) -> MeshData | None:
    """The stored mesh, or None (absent or unreadable; a damaged entry is removed)."""
    path = store_dir() / f"{key}.npz"
    try:
        with np.load(path, allow_pickle=False) as data:
            meta = json.loads(str(data["meta"]))
            vertices, faces = data["vertices"], data["faces"]
    except FileNotFoundError:
        return None
    except (OSError, ValueError, KeyError, EOFError):
        path.unlink(missing_ok=True)
        return None
    rgba = tuple(meta["rgba"]) if meta["rgba"] is not None else None
    return MeshData(vertices, faces, rgba, bool(meta["textured"]))


def store(key: str, mesh: MeshData) -> None:
    """Write one entry atomically; a cache that cannot be written is skipped, never an error."""
    directory = store_dir()
    meta = json.dumps({"rgba": list(mesh.rgba) if mesh.rgba else None, "textured": mesh.textured})
    try:
        directory.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=directory, suffix=".tmp")
        with os.fdopen(fd, "wb") as stream:
            np.savez(stream, vertices=mesh.vertices, faces=mesh.faces, meta=np.array(meta))
        os.replace(tmp, directory / f"{key}.npz")
    except OSError:
        return


def clear() -> int:
    """Remove every stored mesh; return how many entries went."""
    directory = store_dir()
    if not directory.is_dir():
        return 0
    entries = [p for p in directory.iterdir() if p.suffix in (".npz", ".tmp") and p.is_file()]
    for path in entries:
        path.unlink(missing_ok=True)
    return sum(p.suffix == ".npz" for p in entries)
